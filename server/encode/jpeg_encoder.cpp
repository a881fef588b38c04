#include "server/encode/jpeg_encoder.hpp"

#include <stdexcept>

#include <turbojpeg.h>

namespace downpour::encode {

JpegEncoder::JpegEncoder() : handle_(tjInitCompress()) {
  if (!handle_) throw std::runtime_error("tjInitCompress failed");
}

JpegEncoder::~JpegEncoder() { tjDestroy(static_cast<tjhandle>(handle_)); }

std::string JpegEncoder::encode(const RgbaImage& image, int quality) {
  unsigned char* jpeg = nullptr;  // TurboJPEG keeps and grows this buffer inside the handle's call
  unsigned long size = 0;
  const int rc =
      tjCompress2(static_cast<tjhandle>(handle_), image.pixels, image.width, 0, image.height,
                  TJPF_RGBA, &jpeg, &size, TJSAMP_420, quality, TJFLAG_BOTTOMUP | TJFLAG_FASTDCT);
  if (rc != 0) {
    const std::string error = tjGetErrorStr2(static_cast<tjhandle>(handle_));
    tjFree(jpeg);
    throw std::runtime_error("JPEG encoding failed: " + error);
  }
  std::string out(reinterpret_cast<const char*>(jpeg), size);
  tjFree(jpeg);
  return out;
}

}  // namespace downpour::encode
