#include "server/encode/ground_truth.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <stdexcept>

#include "server/encode/png_encoder.hpp"

namespace downpour::encode {

void water_mask(const std::uint8_t* frame, const std::uint8_t* clean, std::size_t pixels,
                std::uint8_t* mask) {
  for (std::size_t i = 0; i < pixels; ++i) {
    const std::uint8_t* a = frame + i * 4;
    const std::uint8_t* b = clean + i * 4;
    const int d = std::max({std::abs(a[0] - b[0]), std::abs(a[1] - b[1]), std::abs(a[2] - b[2])});
    mask[i] = static_cast<std::uint8_t>(d > kWaterMaskFloor ? d : 0);
  }
}

std::string water_mask_png(const std::vector<std::uint8_t>& frame,
                           const std::vector<std::uint8_t>& clean, int width, int height) {
  const std::size_t pixels = static_cast<std::size_t>(width) * height;
  if (frame.size() != pixels * 4 || clean.size() != pixels * 4)
    throw std::invalid_argument("a water mask needs two images of its size");
  std::vector<std::uint8_t> mask(pixels);
  water_mask(frame.data(), clean.data(), pixels, mask.data());
  return encode_png(mask.data(), width, height, PngFormat::kGrey8, RowOrder::kBottomUp);
}

std::uint16_t depth_cm(float metres) {
  if (!(metres > 0.0f)) return 0;  // the sky (and NaN)
  const float cm = std::round(metres * 100.0f);
  return cm >= 65535.0f ? std::uint16_t{65535} : static_cast<std::uint16_t>(std::max(cm, 1.0f));
}

std::string depth_png(const std::vector<float>& metres, int width, int height) {
  const std::size_t pixels = static_cast<std::size_t>(width) * height;
  if (metres.size() != pixels) throw std::invalid_argument("a depth of the wrong size");
  std::vector<std::uint16_t> cm(pixels);
  std::transform(metres.begin(), metres.end(), cm.begin(), depth_cm);
  return encode_png(cm.data(), width, height, PngFormat::kGrey16, RowOrder::kBottomUp);
}

}  // namespace downpour::encode
