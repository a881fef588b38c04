// JPEG encoding through the TurboJPEG API. One encoder per thread (a TurboJPEG handle is not
// shared); its output buffer is reused between frames.
#pragma once

#include <cstdint>
#include <string>

namespace downpour::encode {

struct RgbaImage {
  const std::uint8_t* pixels = nullptr;  // RGBA8, rows bottom-up as GL reads them back
  int width = 0;
  int height = 0;
};

class JpegEncoder {
 public:
  JpegEncoder();
  ~JpegEncoder();
  JpegEncoder(const JpegEncoder&) = delete;
  JpegEncoder& operator=(const JpegEncoder&) = delete;

  // 4:2:0 chroma, quality 1..100. Throws std::runtime_error on failure.
  std::string encode(const RgbaImage& image, int quality);

 private:
  void* handle_;
};

}  // namespace downpour::encode
