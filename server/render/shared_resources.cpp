// The resources the passes share (frame_context.hpp's SharedResources): the noise, the asphalt's
// and the setts' reliefs and their horizon maps, uploaded once and bound to their units.
#include <memory>
#include <stdexcept>
#include <vector>

#include "server/render/cpu/procedural_textures.hpp"
#include "server/render/cpu/relief.hpp"
#include "server/render/cpu/shader_interface.hpp"
#include "server/render/frame_context.hpp"

namespace downpour::render {

namespace {

Texture upload_repeating(const Image8& image, bool mipmaps) {
  int levels = 1;
  if (mipmaps) {
    for (int s = image.width; s > 1; s /= 2) ++levels;
  }
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

// The setts' relief and both reliefs' horizon maps: one array, the asphalt's layers first, packed
// (relief::packed_layer).
void upload_reliefs(SharedResources& shared, const std::shared_ptr<const relief::RoadReliefs>& r) {
  std::vector<float> setts_unit = r->setts.height_m;  // back to [0, 1] for the texture
  for (float& h : setts_unit) h /= relief::kSettsDepthM;
  shared.setts = upload_repeating(
      relief_image(setts_unit, r->setts.size, relief::kSettsDepthM / r->setts.texel_m), true);
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
      SharedResources{upload_repeating(make_noise(256, 1), true),
                      upload_repeating(make_asphalt_relief(512, 2), true), FullscreenTriangle(),
                      Texture(), Texture(), 0, nullptr});
  upload_reliefs(*shared, relief::road_reliefs(kHorizonDirections));
  glBindTextureUnit(texture_unit::kNoise, shared->noise.id());
  glBindTextureUnit(texture_unit::kAsphalt, shared->asphalt.id());
  glBindTextureUnit(texture_unit::kSetts, shared->setts.id());
  glBindTextureUnit(texture_unit::kHorizon, shared->horizon.id());
  return shared;
}

}  // namespace downpour::render
