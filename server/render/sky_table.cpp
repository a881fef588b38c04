#include "server/render/sky_table.hpp"

#include <algorithm>
#include <cmath>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "server/render/cpu/shader_interface.hpp"
#include "server/render/cpu/sky_scattering.hpp"

namespace downpour::render {

namespace {

constexpr std::size_t kCacheLimit = 32;

float luminance(const glm::vec3& c) { return glm::dot(c, glm::vec3(0.2126f, 0.7152f, 0.0722f)); }

}  // namespace

SkyTable::SkyTable() {
  texture_ = make_texture_2d(GL_RGBA16F, kSkyTableWidth, kSkyTableHeight);
  glTextureParameteri(texture_.id(), GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTextureParameteri(texture_.id(), GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTextureParameteri(texture_.id(), GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTextureParameteri(texture_.id(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  const std::vector<float> zero(static_cast<std::size_t>(kSkyTableWidth) * kSkyTableHeight * 4);
  glTextureSubImage2D(texture_.id(), 0, 0, 0, kSkyTableWidth, kSkyTableHeight, GL_RGBA, GL_FLOAT,
                      zero.data());
  glBindTextureUnit(texture_unit::kSky, texture_.id());
}

const std::vector<glm::vec3>& SkyTable::scattered(int quarter_degrees) {
  auto it = cache_.find(quarter_degrees);
  if (it != cache_.end()) return it->second;
  if (cache_.size() >= kCacheLimit) cache_.clear();  // a sun that keeps moving: start again
  return cache_.emplace(quarter_degrees, clear_sky_table(quarter_degrees / 4.0)).first->second;
}

void SkyTable::show(const Atmosphere& a) {
  // What the table depends on: the same air as the last frame's (a session's every frame, as a
  // rule) leaves it as it is.
  const int quarter_degrees =
      static_cast<int>(std::lround(std::clamp(a.sun_altitude_deg, -20.0f, 90.0f) * 4.0f));
  const Shown key{quarter_degrees, a.overcast, a.clear_zenith, a.clear_horizon};
  if (shown_ && *shown_ == key) return;
  shown_ = key;
  const float clear = 1.0f - a.overcast;
  texels_.assign(static_cast<std::size_t>(kSkyTableWidth) * kSkyTableHeight * 4, 0.0f);
  if (clear > 0.0f) {
    const std::vector<glm::vec3>& sky = scattered(quarter_degrees);
    // The gradient it replaces (its rows' v is the shader's sqrt(sin elevation)), and the scale
    // that gives the scattered sky the gradient's mean luminance over the table: the exposure
    // stays the frame's; the colours and where the light lies come from the scattering.
    const auto gradient = [&](std::size_t k) {
      const float v = static_cast<float>(k / kSkyTableWidth) / (kSkyTableHeight - 1);
      return glm::mix(a.clear_horizon, a.clear_zenith, v);
    };
    float sky_sum = 0.0f, gradient_sum = 0.0f;
    for (std::size_t k = 0; k < sky.size(); ++k) {
      sky_sum += luminance(sky[k]);
      gradient_sum += luminance(gradient(k));
    }
    const float scale = sky_sum > 0.0f ? gradient_sum / sky_sum : 0.0f;
    // Round a low sun the scattered sky is tens of times brighter than elsewhere: softly capped
    // at the gradient's horizon (the sun's own glow and disc are the shaders'), so that
    // a bright patch of sky does not blow out the frame and the drops in front of it still show.
    const float cap = luminance(a.clear_horizon);
    for (std::size_t k = 0; k < sky.size(); ++k) {
      glm::vec3 c = sky[k] * scale;
      const float l = luminance(c) / std::max(cap, 1e-6f);
      c /= std::sqrt(1.0f + l * l);
      const glm::vec3 d = (c - gradient(k)) * clear;
      texels_[4 * k] = d.x, texels_[4 * k + 1] = d.y, texels_[4 * k + 2] = d.z;
    }
  }
  glTextureSubImage2D(texture_.id(), 0, 0, 0, kSkyTableWidth, kSkyTableHeight, GL_RGBA, GL_FLOAT,
                      texels_.data());
}

}  // namespace downpour::render
