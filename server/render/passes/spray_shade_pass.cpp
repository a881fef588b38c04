// The spray's colour (spray_pass.hpp): the liquid shaded where a sphere was hit, the clouds'
// optical depth, and that haze over the layer.
#include "server/render/cpu/shader_interface.hpp"
#include "server/render/passes/spray_pass.hpp"

namespace downpour::render {
namespace {

// Road spray is dirty water: absorption per metre, red most (pure water's is far less).
const glm::vec3 kAbsorption(3.0f, 2.0f, 1.6f);
constexpr float kHazeSoftM = 1.0f;  // the haze fades over this where the scene comes nearer

}  // namespace

SprayShadePass::SprayShadePass(SharedResources&, const SprayPass& spray)
    : spray_(spray),
      program_("spray_runs.vert", "spray_shade.frag"),
      u_size_(program_.uniform("u_size")),
      u_tan_(program_.uniform("u_tan")),
      u_to_world_(program_.uniform("u_view_to_world")),
      u_near_(program_.uniform("u_near")),
      u_scale_(program_.uniform("u_scale")),
      u_absorption_(program_.uniform("u_absorption")) {}

void SprayShadePass::execute(const FrameContext& frame, const FrameResources& resources) {
  const TargetTexture& layer = resources.transient(Resource::kSprayLayer).colour;
  program_.use();
  u_size_.set(glm::vec2(static_cast<float>(layer.width), static_cast<float>(layer.height)));
  u_tan_.set(glm::vec2(static_cast<float>(frame.camera.tan_half_fov_x),
                       static_cast<float>(frame.camera.tan_half_fov_y)));
  u_to_world_.set(glm::transpose(glm::mat4(glm::mat3(frame.camera.view))));
  u_near_.set(frame.camera.near_m);
  u_scale_.set(SprayPass::kScale);
  u_absorption_.set(kAbsorption);
  runs_.draw(spray_.liquid_runs());
}

SprayHazePass::SprayHazePass(SharedResources&, const SprayPass& spray)
    : spray_(spray),
      program_("spray_haze.vert", "spray_haze.frag"),
      u_projection_(program_.uniform("u_projection")) {
  vao_ = make_vertex_array();
  clouds_ = make_buffer();
}

void SprayHazePass::execute(const FrameContext& frame, const FrameResources& resources) {
  const TargetTexture& haze = resources.transient(Resource::kSprayHaze).colour;
  if (spray_.cpu_splat()) {  // drawn by the spray pass
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTextureSubImage2D(haze.texture, 0, 0, 0, haze.width, haze.height, GL_RG, GL_FLOAT,
                        spray_.haze_pixels().data());
    return;
  }
  packed_.clear();
  for (const SprayHazeBall& h : spray_.clouds()) {
    packed_.emplace_back(h.ball.centre, h.ball.radius);
    packed_.emplace_back(h.depth, 0.0f, 0.0f, 0.0f);
  }
  glNamedBufferData(clouds_.id(), static_cast<GLsizeiptr>(packed_.size() * sizeof(glm::vec4)),
                    packed_.data(), GL_STREAM_DRAW);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, storage_buffer::kHazeBuffer, clouds_.id());
  program_.use();
  u_projection_.set(frame.camera.projection);
  glBindVertexArray(vao_.id());
  glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, static_cast<GLsizei>(spray_.clouds().size()));
}

// The light the droplets scatter: the sky's and the scene's around them, as the rain's. (Linear:
// the shaders add the lamps' light where their beams pass, then encode it.)
glm::vec3 spray_haze_light(const Atmosphere& atm) {
  return glm::mix(atm.sky_horizon, atm.ambient, 0.4f) * 0.95f + atm.sun_radiance * 0.05f;
}

SprayHazeOverPass::SprayHazeOverPass(SharedResources&, const SprayPass& spray)
    : spray_(spray),
      program_("spray_runs.vert", "spray_haze_composite.frag"),
      u_light_(program_.uniform("u_light")),
      u_near_(program_.uniform("u_near")),
      u_soft_(program_.uniform("u_soft_m")) {}

void SprayHazeOverPass::execute(const FrameContext& frame, const FrameResources&) {
  program_.use();
  u_light_.set(spray_haze_light(frame.atmosphere));
  u_near_.set(frame.camera.near_m);
  u_soft_.set(kHazeSoftM);
  runs_.draw(spray_.runs());
}

}  // namespace downpour::render
