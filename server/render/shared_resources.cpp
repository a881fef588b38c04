// The resources the passes share (frame_context.hpp's SharedResources): the noise, the asphalt's
// and the setts' reliefs in one array and their horizon maps, uploaded once and bound to their
// units.
#include <memory>
#include <stdexcept>
#include <vector>

#include "server/render/cpu/procedural_textures.hpp"
#include "server/render/cpu/relief.hpp"
#include "server/render/cpu/shader_interface.hpp"
#include "server/render/frame_context.hpp"

namespace downpour::render {

namespace {

// A full mip chain's levels for a square of this side.
int mip_levels(int side) {
  int levels = 1;
  for (int s = side; s > 1; s /= 2) ++levels;
  return levels;
}

Texture upload_repeating(const Image8& image, bool mipmaps) {
  const int levels = mipmaps ? mip_levels(image.width) : 1;
  Texture t = make_texture_2d(GL_RGBA8, image.width, image.height, levels);
  glTextureSubImage2D(t.id(), 0, 0, 0, image.width, image.height, GL_RGBA, GL_UNSIGNED_BYTE,
                      image.rgba.data());
  if (mipmaps) glGenerateTextureMipmap(t.id());
  glTextureParameteri(t.id(), GL_TEXTURE_WRAP_S, GL_REPEAT);
  glTextureParameteri(t.id(), GL_TEXTURE_WRAP_T, GL_REPEAT);
  return t;
}

// The relief shadows' azimuths (seed 002: 16 or 32).
constexpr int kHorizonDirections = 32;

// The road's two reliefs in one array over one tile (relief::kGroundTileM), so that the road reads
// either with one fetch (llvmpipe pays for every fetch on every pixel: a second texture for the
// setts cost ROAD's road pass 1.4 ms): the asphalt's 1.5 m tile twice each way, texel for texel,
// and the setts' 1 m tile three times, resampled. Mipmapped.
Texture ground_reliefs(const relief::RoadReliefs& r) {
  static_assert(relief::kGroundTileM == 2.0f * relief::kAsphaltTileM &&
                relief::kGroundTileM == 3.0f * relief::kSettsTileM);
  constexpr int kSize = 1024;
  const Image8 asphalt = make_asphalt_relief(kSize / 2, 2);
  std::vector<float> setts(static_cast<std::size_t>(kSize) * kSize);
  const float to_setts = relief::kGroundTileM / kSize / r.setts.texel_m;  // (their texels)
  for (int y = 0; y < kSize; ++y) {
    for (int x = 0; x < kSize; ++x) {
      setts[static_cast<std::size_t>(y) * kSize + x] =
          r.setts.sample((x + 0.5f) * to_setts - 0.5f, (y + 0.5f) * to_setts - 0.5f) /
          relief::kSettsDepthM;  // (back to [0, 1])
    }
  }
  const Image8 setts_image =
      relief_image(setts, kSize, relief::kSettsDepthM * kSize / relief::kGroundTileM);
  Texture t = make_texture_2d_array(GL_RGBA8, kSize, kSize, 2, mip_levels(kSize));
  for (int ty = 0; ty < 2; ++ty) {
    for (int tx = 0; tx < 2; ++tx) {
      glTextureSubImage3D(t.id(), 0, tx * asphalt.width, ty * asphalt.height, 0, asphalt.width,
                          asphalt.height, 1, GL_RGBA, GL_UNSIGNED_BYTE, asphalt.rgba.data());
    }
  }
  glTextureSubImage3D(t.id(), 0, 0, 0, 1, kSize, kSize, 1, GL_RGBA, GL_UNSIGNED_BYTE,
                      setts_image.rgba.data());
  glGenerateTextureMipmap(t.id());
  glTextureParameteri(t.id(), GL_TEXTURE_WRAP_S, GL_REPEAT);
  glTextureParameteri(t.id(), GL_TEXTURE_WRAP_T, GL_REPEAT);
  return t;
}

// The road's reliefs and both their horizon maps: one array, the asphalt's layers first, packed
// (relief::packed_layer).
void upload_reliefs(SharedResources& shared, const std::shared_ptr<const relief::RoadReliefs>& r) {
  shared.ground_relief = ground_reliefs(*r);
  const relief::HorizonMaps* maps[] = {&r->asphalt_horizon, &r->setts_horizon};
  const int size = maps[0]->size, n = maps[0]->directions;
  shared.horizon_directions = n;
  shared.reliefs = r;
  shared.horizon = make_texture_2d_array(GL_RGBA8, size, size, 2 * n);
  for (int m = 0; m < 2; ++m) {
    if (maps[m]->size != size || maps[m]->directions != n) {
      throw std::logic_error("the reliefs' horizon maps differ in size");
    }
    for (int k = 0; k < n; ++k) {
      glTextureSubImage3D(shared.horizon.id(), 0, 0, 0, m * n + k, size, size, 1, GL_RGBA,
                          GL_UNSIGNED_BYTE, relief::packed_layer(*maps[m], k).data());
    }
  }
  glTextureParameteri(shared.horizon.id(), GL_TEXTURE_WRAP_S, GL_REPEAT);
  glTextureParameteri(shared.horizon.id(), GL_TEXTURE_WRAP_T, GL_REPEAT);
  glTextureParameteri(shared.horizon.id(), GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTextureParameteri(shared.horizon.id(), GL_TEXTURE_MAG_FILTER, GL_LINEAR);
}

}  // namespace

std::unique_ptr<SharedResources> make_shared_resources() {
  auto shared = std::make_unique<SharedResources>(
      SharedResources{upload_repeating(make_noise(256, 1), true), Texture(), FullscreenTriangle(),
                      Texture(), 0, nullptr});
  upload_reliefs(*shared, relief::road_reliefs(kHorizonDirections));
  glBindTextureUnit(texture_unit::kNoise, shared->noise.id());
  glBindTextureUnit(texture_unit::kGroundRelief, shared->ground_relief.id());
  glBindTextureUnit(texture_unit::kHorizon, shared->horizon.id());
  return shared;
}

}  // namespace downpour::render
