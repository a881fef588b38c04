#include "tests/support/png_io.hpp"

#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <stdexcept>

#include <png.h>

#include "server/encode/png_encoder.hpp"

namespace downpour::testing {

void write_png(const std::string& path, const RgbaImage& image) {
  std::unique_ptr<FILE, int (*)(FILE*)> file(std::fopen(path.c_str(), "wb"), &std::fclose);
  if (!file) throw std::runtime_error("cannot write " + path);
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png_create_info_struct(png);
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    throw std::runtime_error("libpng failed writing " + path);
  }
  png_init_io(png, file.get());
  png_set_IHDR(png, info, image.width, image.height, 8, PNG_COLOR_TYPE_RGBA, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  for (int y = 0; y < image.height; ++y) {
    png_write_row(
        png, const_cast<png_bytep>(&image.pixels[static_cast<std::size_t>(y) * image.width * 4]));
  }
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
}

std::string png_bytes_rgb(int width, int height, const std::vector<std::uint8_t>& rgb) {
  return encode::encode_png(rgb.data(), width, height, encode::PngFormat::kRgb8,
                            encode::RowOrder::kTopDown);
}

std::string png_bytes_grey16(int width, int height, const std::vector<std::uint16_t>& values) {
  return encode::encode_png(values.data(), width, height, encode::PngFormat::kGrey16,
                            encode::RowOrder::kTopDown);
}

RgbaImage read_png(const std::string& path) {
  png_image img{};
  img.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&img, path.c_str()))
    throw std::runtime_error("cannot read " + path);
  img.format = PNG_FORMAT_RGBA;
  RgbaImage out{static_cast<int>(img.width), static_cast<int>(img.height), {}};
  out.pixels.resize(PNG_IMAGE_SIZE(img));
  if (!png_image_finish_read(&img, nullptr, out.pixels.data(), 0, nullptr)) {
    throw std::runtime_error("cannot decode " + path);
  }
  return out;
}

double psnr(const RgbaImage& a, const RgbaImage& b) {
  if (a.width != b.width || a.height != b.height) return 0.0;
  double sum = 0.0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < a.pixels.size(); i += 4) {
    for (int c = 0; c < 3; ++c) {
      const double d = static_cast<double>(a.pixels[i + c]) - b.pixels[i + c];
      sum += d * d;
      ++n;
    }
  }
  if (sum == 0.0) return std::numeric_limits<double>::infinity();
  return 10.0 * std::log10(255.0 * 255.0 / (sum / n));
}

double mean_luma(const RgbaImage& image, int x0, int y0, int x1, int y1) {
  if (x1 < 0) x1 = image.width;
  if (y1 < 0) y1 = image.height;
  double sum = 0.0;
  for (int y = y0; y < y1; ++y) {
    for (int x = x0; x < x1; ++x) {
      const std::uint8_t* p = &image.pixels[(static_cast<std::size_t>(y) * image.width + x) * 4];
      sum += (0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]) / 255.0;
    }
  }
  return sum / std::max(1, (x1 - x0) * (y1 - y0));
}

}  // namespace downpour::testing
