#include "server/render/passes/lamp_glow_pass.hpp"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

#include "server/render/cpu/light_set.hpp"
#include "server/render/cpu/shader_interface.hpp"

namespace downpour::render {

float lamp_glare(const Light& l, const glm::vec3& camera, float lux_exposure, float haze_per_m,
                 glm::vec3* dir_out, float* distance) {
  const glm::vec3 to_camera = camera - l.position;
  const float d = std::max(glm::length(to_camera), 0.3f);
  const glm::vec3 dir = to_camera / d;
  if (dir_out) *dir_out = dir;
  if (distance) *distance = d;
  // A lens shows from anywhere within its outer cone.
  const float peak = std::max({l.intensity_cd.r, l.intensity_cd.g, l.intensity_cd.b});
  if (glm::dot(dir, l.direction) <= l.cos_outer || peak <= 0.0f) return 0.0f;
  return peak * beam_towards(l, dir, 0.03f) / (d * d) * lux_exposure * std::exp(-haze_per_m * d);
}

void lamp_glows(const std::vector<Light>& lights, const glm::vec3& camera, float tan_half_fov_y,
                int height, float lux_exposure, float haze_per_m, std::vector<LampGlow>& glows) {
  glows.clear();
  const float pixels_per_radian = 0.5f * static_cast<float>(height) / tan_half_fov_y;
  for (const Light& l : lights) {
    glm::vec3 dir;
    float d = 0.0f;
    const float glare = lamp_glare(l, camera, lux_exposure, haze_per_m, &dir, &d);
    const float peak = std::max({l.intensity_cd.r, l.intensity_cd.g, l.intensity_cd.b});
    if (glm::dot(dir, l.direction) <= l.cos_outer || peak <= 0.0f) continue;
    const float haze = std::exp(-haze_per_m * d);
    LampGlow g;
    // The halo: half a degree across at a glare of 0.1, growing with its square root.
    const float radius = pixels_per_radian * 0.00873f * std::sqrt(glare / 0.1f);
    g.position_size = glm::vec4(l.position + dir * 0.15f,
                                std::clamp(radius, 1.5f, 0.08f * static_cast<float>(height)));
    g.colour_strength = glm::vec4(l.intensity_cd / peak, std::min(glare * 0.5f, 1.5f));
    // The core: a tail lamp's 4 cd dimmer than a brake lamp's 60 and anything brighter.
    g.core = haze * std::clamp(0.35f + 0.65f * std::sqrt(peak / 60.0f), 0.35f, 1.0f);
    glows.push_back(g);
  }
  constexpr auto kMost = static_cast<std::size_t>(kMaxGlows);
  if (glows.size() > kMost) {
    std::partial_sort(glows.begin(), glows.begin() + kMost, glows.end(),
                      [](const LampGlow& a, const LampGlow& b) {
                        return a.colour_strength.w > b.colour_strength.w;
                      });
    glows.resize(kMost);
  }
}

LampGlowPass::LampGlowPass(SharedResources&)
    : program_("lamp_glow.vert", "lamp_glow.frag"),
      u_glows_(program_.uniform("u_glows")),
      u_pixel_(program_.uniform("u_pixel")) {
  vao_ = make_vertex_array();
}

bool LampGlowPass::wanted(const FrameContext& frame) const {
  return frame.lights && !frame.lights->empty();
}

void LampGlowPass::execute(const FrameContext& frame, const FrameResources& resources) {
  lamp_glows(*frame.lights, frame.camera.position, frame.camera.tan_half_fov_y,
             resources.view_colour.height, frame.atmosphere.lux_exposure,
             frame.atmosphere.fog_density, glows_);
  const std::vector<LampGlow>& glows = glows_;
  if (glows.empty()) return;
  packed_.clear();
  for (const LampGlow& g : glows) {
    packed_.push_back(g.position_size);
    packed_.push_back(g.colour_strength);
    packed_.push_back(glm::vec4(g.core, 0.0f, 0.0f, 0.0f));
  }
  program_.use();
  u_glows_.set(packed_.data(), static_cast<int>(packed_.size()));
  u_pixel_.set(glm::vec2(2.0f / static_cast<float>(resources.view_colour.width),
                         2.0f / static_cast<float>(resources.view_colour.height)));
  glBindVertexArray(vao_.id());
  glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, static_cast<GLsizei>(glows.size()));
}

}  // namespace downpour::render
