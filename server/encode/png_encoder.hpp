// PNG files in memory through libpng: the ground truth's masks and depths (fast compression: most
// of a mask is 0), and the pictures tests send as a client would.
#pragma once

#include <cstdint>
#include <string>

namespace downpour::encode {

enum class PngFormat {
  kGrey8,   // one byte a pixel
  kGrey16,  // one 16-bit value a pixel, in this machine's byte order
  kRgb8,    // three bytes a pixel
};

enum class RowOrder { kTopDown, kBottomUp };

// A PNG of `pixels` (width x height in `format`, rows in `order`), written top-down as PNG's rows
// are. Throws std::runtime_error where libpng fails.
std::string encode_png(const void* pixels, int width, int height, PngFormat format, RowOrder order);

}  // namespace downpour::encode
