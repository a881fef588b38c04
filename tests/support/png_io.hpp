// PNG files for golden images and for looking at what the renderer draws (libpng).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace downpour::testing {

struct RgbaImage {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> pixels;  // RGBA8, rows top-down
};

// Throw std::runtime_error on failure.
void write_png(const std::string& path, const RgbaImage& image);
RgbaImage read_png(const std::string& path);

// PNG files in memory, as a client sends its pictures: 8-bit RGB (rows top-down, 3 bytes a
// pixel), or one 16-bit grey channel.
std::string png_bytes_rgb(int width, int height, const std::vector<std::uint8_t>& rgb);
std::string png_bytes_grey16(int width, int height, const std::vector<std::uint16_t>& values);

// Peak signal-to-noise ratio over RGB, in dB (infinity for identical images).
double psnr(const RgbaImage& a, const RgbaImage& b);
// Mean Rec. 709 luma of RGB in [0, 1] over a pixel rectangle (default the whole image).
double mean_luma(const RgbaImage& image, int x0 = 0, int y0 = 0, int x1 = -1, int y1 = -1);

}  // namespace downpour::testing
