#pragma once

#include <vector>

#include <glm/vec4.hpp>

#include "server/render/pass.hpp"

namespace downpour::render {

struct Light;

// A lamp as the camera sees it: a lens that a low-resolution view would lose (a tail lamp 25 m
// off is one pixel high at 320 x 180) drawn as a core of at least a pixel, and the glare of a
// lamp that shines at the camera as a halo around it, which the drops on the glass then refract
// (the COCKPIT view's glass passes come after this one): seen through wet glass, bright lamps
// bloom. No halo from a lamp that points away (the headlights of the car ahead) or cuts its beam
// off below the camera (an oncoming car's dipped beam but for its stray light).
struct LampGlow {
  glm::vec4 position_size{0.0f};    // xyz world (a little towards the camera from the lamp), w halo
                                    // radius in pixels
  glm::vec4 colour_strength{0.0f};  // rgb the lens's colour, w the halo's peak (display units)
  float core = 0.0f;                // the core's brightness: 1 for a lens that faces the camera
};

// A lamp's glare at `camera`: the illuminance it gives there (its beam towards the camera, a
// dipped beam leaving 3% stray light above its cut-off, through the haze), as the radiance a
// white card there would show (display units, the frame's exposure per lux); 0 for a lamp that
// points away. `dir` (if given) receives the unit direction from the lamp to the camera, and
// `distance` the distance.
float lamp_glare(const Light& light, const glm::vec3& camera, float lux_exposure, float haze_per_m,
                 glm::vec3* dir = nullptr, float* distance = nullptr);

// The glows of the frame's lamps seen from `camera` in a view `height` pixels high with the
// vertical half-angle tan_half_fov_y, under the frame's exposure (radiance per lux) and haze
// (extinction per metre); at most kMaxGlows (shader_interface.hpp), the strongest. Into `glows`
// (cleared first: kept from frame to frame, no allocation once it has grown).
void lamp_glows(const std::vector<Light>& lights, const glm::vec3& camera, float tan_half_fov_y,
                int height, float lux_exposure, float haze_per_m, std::vector<LampGlow>& glows);

class LampGlowPass final : public Pass {
 public:
  explicit LampGlowPass(SharedResources& shared);
  const PassDecl& decl() const override { return decl_; }
  bool wanted(const FrameContext& frame) const override;
  void execute(const FrameContext& frame, const FrameResources& resources) override;

 private:
  const PassDecl decl_{
      "lamp_glow", {}, {Resource::kViewColour}, {DepthTest::kNearer, false, Blend::kPremultiplied}};
  ShaderProgram program_;
  Uniform u_glows_, u_pixel_;
  VertexArray vao_;
  std::vector<LampGlow> glows_;
  std::vector<glm::vec4> packed_;
};

}  // namespace downpour::render
