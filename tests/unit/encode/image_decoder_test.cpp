// Client pictures decoded: JPEG and PNG of the view's size to BGRX rows bottom-up, 16-bit grey PNG
// depths exactly, and every kind of bad input refused with a message that says what is wrong.
#include "server/encode/image_decoder.hpp"

#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "server/encode/jpeg_encoder.hpp"
#include "tests/support/png_io.hpp"

namespace downpour::encode {
namespace {

constexpr int kW = 48;
constexpr int kH = 20;

// RGB rows top-down: red across, green down, blue fixed.
std::vector<std::uint8_t> pattern() {
  std::vector<std::uint8_t> rgb(static_cast<std::size_t>(kW) * kH * 3);
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) {
      std::uint8_t* p = &rgb[(static_cast<std::size_t>(y) * kW + x) * 3];
      p[0] = static_cast<std::uint8_t>(x * 5);
      p[1] = static_cast<std::uint8_t>(y * 12);
      p[2] = 77;
    }
  }
  return rgb;
}

// The RGB of BGRX pixels, rows top-down (the decoder's run bottom-up, as GL takes them).
std::vector<std::uint8_t> rgb_of(const BgrxPixels& p) {
  std::vector<std::uint8_t> rgb;
  for (int y = p.height - 1; y >= 0; --y) {
    for (int x = 0; x < p.width; ++x) {
      const std::uint8_t* at = &p.bgrx[(static_cast<std::size_t>(y) * p.width + x) * 4];
      rgb.insert(rgb.end(), {at[2], at[1], at[0]});
    }
  }
  return rgb;
}

std::string message_of(const std::function<void()>& fn) {
  try {
    fn();
  } catch (const DecodeError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(ImageDecoderTest, PngRgbDecodesExactly) {
  const std::vector<std::uint8_t> rgb = pattern();
  const BgrxPixels out = decode_bgrx(testing::png_bytes_rgb(kW, kH, rgb), kW, kH);
  EXPECT_EQ(out.width, kW);
  EXPECT_EQ(out.height, kH);
  EXPECT_EQ(rgb_of(out), rgb);
}

TEST(ImageDecoderTest, PngWithAlphaKeepsItsColour) {
  testing::RgbaImage rgba{kW, kH, std::vector<std::uint8_t>(static_cast<std::size_t>(kW) * kH * 4)};
  const std::vector<std::uint8_t> rgb = pattern();
  for (std::size_t i = 0; i < rgb.size() / 3; ++i) {
    for (int c = 0; c < 3; ++c) rgba.pixels[i * 4 + c] = rgb[i * 3 + c];
    rgba.pixels[i * 4 + 3] = 128;
  }
  const std::string path = ::testing::TempDir() + "decoder_rgba.png";
  testing::write_png(path, rgba);
  std::string bytes;
  {
    std::FILE* f = std::fopen(path.c_str(), "rb");
    ASSERT_NE(f, nullptr);
    char buf[4096];
    for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, f)) > 0;) bytes.append(buf, n);
    std::fclose(f);
  }
  EXPECT_EQ(rgb_of(decode_bgrx(bytes, kW, kH)), rgb);
}

TEST(ImageDecoderTest, JpegDecodesClose) {
  // The encoder takes RGBA rows bottom-up.
  const std::vector<std::uint8_t> rgb = pattern();
  std::vector<std::uint8_t> rgba(static_cast<std::size_t>(kW) * kH * 4);
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) {
      const std::size_t from = (static_cast<std::size_t>(y) * kW + x) * 3;
      const std::size_t to = (static_cast<std::size_t>(kH - 1 - y) * kW + x) * 4;
      for (int c = 0; c < 3; ++c) rgba[to + c] = rgb[from + c];
      rgba[to + 3] = 255;
    }
  }
  JpegEncoder encoder;
  const std::string jpeg = encoder.encode({rgba.data(), kW, kH}, 95);
  ASSERT_TRUE(is_jpeg(jpeg));
  const BgrxPixels out = decode_bgrx(jpeg, kW, kH);
  const std::vector<std::uint8_t> seen = rgb_of(out);
  ASSERT_EQ(seen.size(), rgb.size());
  double error = 0.0;
  for (std::size_t i = 0; i < rgb.size(); ++i) error += std::abs(seen[i] - rgb[i]);
  EXPECT_LT(error / rgb.size(), 4.0) << "mean absolute error, levels";
}

TEST(ImageDecoderTest, Grey16KeepsEveryValue) {
  std::vector<std::uint16_t> depth(static_cast<std::size_t>(kW) * kH);
  for (std::size_t i = 0; i < depth.size(); ++i) depth[i] = static_cast<std::uint16_t>(i * 1361);
  const Grey16Pixels out = decode_png_grey16(testing::png_bytes_grey16(kW, kH, depth), kW, kH);
  for (int y = 0; y < kH; ++y) {  // (rows bottom-up)
    for (int x = 0; x < kW; ++x)
      ASSERT_EQ(out.values[static_cast<std::size_t>(kH - 1 - y) * kW + x], depth[y * kW + x]);
  }
}

TEST(ImageDecoderTest, TheWrongSizeIsRefusedNamingBoth) {
  const std::string png = testing::png_bytes_rgb(kW, kH, pattern());
  EXPECT_EQ(message_of([&] { decode_bgrx(png, 64, 36); }), "the PNG is 48x20, the view is 64x36");
  const std::vector<std::uint16_t> depth(static_cast<std::size_t>(kW) * kH, 100);
  EXPECT_EQ(
      message_of([&] { decode_png_grey16(testing::png_bytes_grey16(kW, kH, depth), kW + 1, kH); }),
      "the PNG is 48x20, the view is 49x20");
}

TEST(ImageDecoderTest, BadBytesAreRefused) {
  EXPECT_EQ(message_of([] { decode_bgrx("", kW, kH); }), "empty");
  EXPECT_EQ(message_of([] { decode_bgrx("GIF89a....", kW, kH); }), "neither a JPEG nor a PNG");
  // Cut short, and damaged in the middle.
  const std::string png = testing::png_bytes_rgb(kW, kH, pattern());
  EXPECT_NE(message_of([&] {
              decode_bgrx(png.substr(0, png.size() / 2), kW, kH);
            }).find("the PNG does not decode"),
            std::string::npos);
  std::string damaged = png;
  for (std::size_t i = 60; i < damaged.size() - 20; i += 7) damaged[i] = static_cast<char>(0x5a);
  EXPECT_NE(message_of([&] { decode_bgrx(damaged, kW, kH); }).find("does not decode"),
            std::string::npos);
  EXPECT_NE(message_of([] {
              decode_bgrx(std::string("\xff\xd8\xff\xe0garbage", 11), kW, kH);
            }).find("JPEG"),
            std::string::npos);
  // A depth must be a 16-bit grey PNG.
  EXPECT_NE(message_of([&] { decode_png_grey16(png, kW, kH); }).find("not a 16-bit grey PNG"),
            std::string::npos);
  EXPECT_NE(message_of([] {
              decode_png_grey16(std::string("\xff\xd8\xff", 3), kW, kH);
            }).find("a depth must be a PNG"),
            std::string::npos);
}

}  // namespace
}  // namespace downpour::encode
