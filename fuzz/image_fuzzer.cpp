// Fuzz target: a client's picture and depth (Update.client_images) -> the decoders and the
// checks the service runs before a picture reaches a session. The first byte picks: the picture
// decoder, the depth decoder, or a whole ClientImage (its bytes split into picture and depth)
// through to_client_images. A picture accepted must hold exactly its view's pixels, and a depth
// finite non-negative metres; nothing may crash, leak or hit undefined behaviour.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>
#include <vector>

#include "downpour/v1/downpour.pb.h"
#include "server/encode/image_decoder.hpp"
#include "server/rpc/validation.hpp"

namespace {

using namespace downpour;

constexpr int kW = 48, kH = 20;

void require(bool ok) {
  if (!ok) std::abort();  // an invariant of an accepted picture broke: a finding
}

std::vector<sim::ViewSpec> views() {
  sim::ViewSpec cockpit = sim::view_spec(sim::View::kCockpit, kW, kH);
  cockpit.background = sim::Background::kClient;
  return {cockpit, sim::view_spec(sim::View::kRoad, kW, kH)};
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 2) return 0;
  const std::string_view bytes(reinterpret_cast<const char*>(data + 2), size - 2);
  switch (data[0] % 3) {
    case 0:
      try {
        const encode::BgrxPixels p = encode::decode_bgrx(bytes, kW, kH);
        require(p.width == kW && p.height == kH && p.bgrx.size() == std::size_t{kW} * kH * 4);
      } catch (const encode::DecodeError&) {
      }
      return 0;
    case 1:
      try {
        const encode::Grey16Pixels p = encode::decode_png_grey16(bytes, kW, kH);
        require(p.values.size() == std::size_t{kW} * kH);
      } catch (const encode::DecodeError&) {
      }
      return 0;
    default: {
      // The second byte: where the picture ends and the depth begins, and the depth's encoding.
      const std::size_t split = bytes.size() * data[1] / 255;
      v1::Update update;
      v1::ClientImage* c = update.add_client_images();
      c->set_view(v1::VIEW_COCKPIT);
      c->set_image(std::string(bytes.substr(0, split)));
      c->set_depth(std::string(bytes.substr(split)));
      c->set_depth_encoding(static_cast<v1::DepthEncoding>(data[1] % 4));
      sim::Update out;
      if (!rpc::to_client_images(update, "update", views(), &out).ok()) return 0;
      const auto& image = out.client_images[static_cast<int>(sim::View::kCockpit)];
      require(image && image->width == kW && image->height == kH);
      require(image->bgrx.size() == std::size_t{kW} * kH * 4);
      require(image->depth_m.empty() || image->depth_m.size() == std::size_t{kW} * kH);
      for (const float d : image->depth_m) require(std::isfinite(d) && d >= 0.0f);
      return 0;
    }
  }
}
