// The spray body's front depth smoothed (seed 001, section 4), over the tiles the body covers:
// plane fitting (9 x 9, 3 passes) or the bilateral filter (7 x 7, 22 passes), as a ping-pong
// between kSprayBodyFront and a scratch texture of the pass's own that ends in kSprayBodyFront.
#include <cmath>

#include "server/render/cpu/shader_interface.hpp"
#include "server/render/passes/spray_pass.hpp"

namespace downpour::render {
namespace {

// The smoothing's figures (seed 001, section 4): plane fitting 9 x 9 x 3 with the weight's sigma
// about two parcel radii; the bilateral filter 7 x 7 x 22, sigma1 = w / (2 sqrt 2) over a kernel
// of width w, sigma2 = 2 sqrt 2 r.
constexpr int kPlanePasses = 3;
constexpr float kPlaneSigmaM = 0.08f, kPlaneMaxShiftM = 0.15f;
constexpr int kBilateralRadius = 3, kBilateralPasses = 22;
constexpr float kBodyRadiusM = 0.04f;

}  // namespace

SpraySmoothPass::SpraySmoothPass(SharedResources&, const SprayPass& spray)
    : spray_(spray),
      plane_program_("spray_runs.vert", "spray_plane_fit.frag"),
      bilateral_program_("spray_runs.vert", "spray_bilateral.frag"),
      u_plane_size_(plane_program_.uniform("u_size")),
      u_plane_tan_(plane_program_.uniform("u_tan")),
      u_plane_sigma_(plane_program_.uniform("u_sigma")),
      u_plane_shift_(plane_program_.uniform("u_max_shift")),
      u_bilateral_size_(bilateral_program_.uniform("u_size")),
      u_bilateral_sigma_px_(bilateral_program_.uniform("u_sigma_px")),
      u_bilateral_sigma_z_(bilateral_program_.uniform("u_sigma_z")) {
  // The runs' depth against the mask: the smoothing's between the spray's and the body's marks.
  plane_program_.uniform("u_depth").set(0.5f * (kSprayMaskSpray + kSprayMaskBody));
  bilateral_program_.uniform("u_depth").set(0.5f * (kSprayMaskSpray + kSprayMaskBody));
}

void SpraySmoothPass::execute(const FrameContext& frame, const FrameResources& resources) {
  // No body: nothing reads the body's front (the shading reads it where the mask holds the body).
  if (spray_.body().empty()) return;
  const glm::vec2 tan(static_cast<float>(frame.camera.tan_half_fov_x),
                      static_cast<float>(frame.camera.tan_half_fov_y));
  smooth(resources.transient(Resource::kSprayMaps), resources.transient(Resource::kSprayBodyFront),
         spray_.body_runs(), tan);
}

SpraySmoothPass::Scratch& SpraySmoothPass::scratch(int width, int height) {
  for (Scratch& s : scratch_) {
    if (s.width == width && s.height == height) return s;
  }
  if (scratch_.size() >= 4) scratch_.erase(scratch_.begin());
  Scratch s;
  s.width = width;
  s.height = height;
  s.texture = make_texture_2d(GL_R32F, width, height);
  glTextureParameteri(s.texture.id(), GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTextureParameteri(s.texture.id(), GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glTextureParameteri(s.texture.id(), GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTextureParameteri(s.texture.id(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  GLuint id = 0;
  glCreateFramebuffers(1, &id);
  s.fbo = Framebuffer(id);
  glNamedFramebufferTexture(id, GL_COLOR_ATTACHMENT0, s.texture.id(), 0);
  scratch_.push_back(std::move(s));
  return scratch_.back();
}

void SpraySmoothPass::smooth(const FrameTarget& maps, const FrameTarget& out,
                             const std::vector<glm::vec4>& runs, glm::vec2 tan) {
  const int width = out.colour.width, height = out.colour.height;
  const int passes = smoothing_ == SpraySmoothing::kPlaneFit    ? kPlanePasses
                     : smoothing_ == SpraySmoothing::kBilateral ? kBilateralPasses
                                                                : 0;
  if (passes == 0 || runs.empty()) {
    // The maps' own front (their first channel).
    glBlitNamedFramebuffer(maps.fbo, out.fbo, 0, 0, width, height, 0, 0, width, height,
                           GL_COLOR_BUFFER_BIT, GL_NEAREST);
    return;
  }
  Scratch& s = scratch(width, height);
  // (Each time: a GL name may be reused for another texture once the maps are made again.)
  glNamedFramebufferTexture(s.fbo.id(), GL_DEPTH_ATTACHMENT, maps.depth.texture, 0);
  const float far[4] = {kSprayFar, kSprayFar, kSprayFar, kSprayFar};
  glClearNamedFramebufferfv(s.fbo.id(), GL_COLOR, 0, far);
  const glm::vec2 size(static_cast<float>(width), static_cast<float>(height));
  if (smoothing_ == SpraySmoothing::kPlaneFit) {
    plane_program_.use();
    u_plane_size_.set(size);
    u_plane_tan_.set(tan);
    u_plane_sigma_.set(kPlaneSigmaM);
    u_plane_shift_.set(kPlaneMaxShiftM);
  } else {
    bilateral_program_.use();
    u_bilateral_size_.set(size);
    u_bilateral_sigma_px_.set((2.0f * kBilateralRadius + 1.0f) / (2.0f * std::sqrt(2.0f)));
    u_bilateral_sigma_z_.set(2.0f * std::sqrt(2.0f) * kBodyRadiusM);
  }
  glViewport(0, 0, width, height);
  // The first pass reads the maps' front; each writes where the next reads, the last into `out`.
  GLuint body_front = maps.colour.texture;
  for (int pass = 0; pass < passes; ++pass) {
    const bool last_parity = (passes - 1 - pass) % 2 == 0;
    glBindTextureUnit(texture_unit::kSpraySmooth, body_front);
    glBindFramebuffer(GL_FRAMEBUFFER, last_parity ? out.fbo : s.fbo.id());
    runs_.draw(runs);
    body_front = last_parity ? out.colour.texture : s.texture.id();
  }
}

}  // namespace downpour::render
