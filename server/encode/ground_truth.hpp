// A frame's ground truth made ready for the wire (the contract's Output), on an encoder thread:
// the water mask from the frame and its clean frame, and the depth in centimetres.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace downpour::encode {

// Differences of this many levels or fewer are not the water's: the mask is 0 there.
inline constexpr int kWaterMaskFloor = 2;

// Per pixel, the largest of the colour channels' differences between two RGBA8 images of `pixels`
// pixels, 0 where it is kWaterMaskFloor or less.
void water_mask(const std::uint8_t* frame, const std::uint8_t* clean, std::size_t pixels,
                std::uint8_t* mask);
// The mask as an 8-bit grey PNG; the images' rows bottom-up, as read back.
std::string water_mask_png(const std::vector<std::uint8_t>& frame,
                           const std::vector<std::uint8_t>& clean, int width, int height);

// A distance in metres as the depth PNG holds it: centimetres, rounded; 0 stays 0 (the sky), and
// 655.35 m or more is 65535.
std::uint16_t depth_cm(float metres);
// Distances (rows bottom-up) as a 16-bit grey PNG of centimetres.
std::string depth_png(const std::vector<float>& metres, int width, int height);

}  // namespace downpour::encode
