// The ground truth's wire forms: the water mask's rule, the depth in centimetres, and the PNGs
// the right way up.
#include "server/encode/ground_truth.hpp"

#include <cstdint>
#include <vector>

#include <gtest/gtest.h>

#include "server/encode/image_decoder.hpp"

namespace downpour::encode {
namespace {

TEST(GroundTruthTest, TheMaskIsTheLargestChannelDifferenceAboveTwoLevels) {
  const std::vector<std::uint8_t> frame = {10, 10, 10, 255, 10,  12, 10, 255,
                                           10, 10, 13, 255, 200, 0,  90, 255};
  const std::vector<std::uint8_t> clean = {10, 10, 10, 0, 10,  10, 10, 0,
                                           10, 10, 10, 0, 100, 40, 95, 0};
  std::uint8_t mask[4];
  water_mask(frame.data(), clean.data(), 4, mask);
  EXPECT_EQ(mask[0], 0);    // the same (alpha is not colour)
  EXPECT_EQ(mask[1], 0);    // 2 levels: not the water's
  EXPECT_EQ(mask[2], 3);    // 3 levels
  EXPECT_EQ(mask[3], 100);  // the largest channel's
}

TEST(GroundTruthTest, DepthIsWholeCentimetresWithTheSkyAtZero) {
  EXPECT_EQ(depth_cm(0.0f), 0);
  EXPECT_EQ(depth_cm(-1.0f), 0);
  EXPECT_EQ(depth_cm(0.001f), 1) << "a surface is never the sky";
  EXPECT_EQ(depth_cm(12.344f), 1234);
  EXPECT_EQ(depth_cm(655.35f), 65535);
  EXPECT_EQ(depth_cm(1e9f), 65535);
}

TEST(GroundTruthTest, PngsComeOutTheRightWayUp) {
  // Two rows, bottom-up as read back: the bottom row differs, the top does not.
  const std::vector<std::uint8_t> frame = {50, 0, 0, 255, 50, 0, 0, 255,
                                           0,  0, 0, 255, 0,  0, 0, 255};
  const std::vector<std::uint8_t> clean(16, 0);
  const BgrxPixels mask = decode_bgrx(water_mask_png(frame, clean, 2, 2), 2, 2);
  EXPECT_EQ(mask.bgrx[0], 50) << "decoded bottom-up, as written";
  EXPECT_EQ(mask.bgrx[8], 0);
  const Grey16Pixels depth = decode_png_grey16(depth_png({1.0f, 2.0f, 0.0f, 700.0f}, 2, 2), 2, 2);
  EXPECT_EQ(depth.values, (std::vector<std::uint16_t>{100, 200, 0, 65535}));
}

}  // namespace
}  // namespace downpour::encode
