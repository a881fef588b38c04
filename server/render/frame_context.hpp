// What every pass sees of the frame it draws, and the GL resources the passes share.
#pragma once

#include <glm/mat4x4.hpp>

#include "server/render/atmosphere.hpp"
#include "server/render/camera.hpp"
#include "server/render/gl_objects.hpp"
#include "server/sim/simulation.hpp"
#include "server/sim/track.hpp"

namespace downpour::render {

struct FrameContext {
  const sim::SceneState& scene;
  const sim::ViewSpec& spec;
  Camera camera;
  Atmosphere atmosphere;
  glm::mat4 vehicle_to_world{1.0f};
  // The view's render target, bound while the passes draw: its framebuffer and attachments.
  GLuint target_fbo = 0;
  GLuint target_colour = 0;
  GLuint target_depth = 0;
};

// Texture units and the uniform block binding fixed across the shaders (common.glsl).
namespace binding {
inline constexpr GLuint kFrameBlock = 0;
inline constexpr GLuint kNoise = 1;
inline constexpr GLuint kAsphalt = 2;
inline constexpr GLuint kMetaballDensity = 3;
inline constexpr GLuint kWaterHeights = 4;
inline constexpr GLuint kWaterMap = 5;
inline constexpr GLuint kSceneBlur = 6;
inline constexpr GLuint kViewColour = 7;
inline constexpr GLuint kViewDepth = 8;
}  // namespace binding

// Resources made once and shared by the passes.
struct SharedResources {
  sim::Track track;
  Texture noise;    // make_noise, repeat
  Texture asphalt;  // make_asphalt_relief, repeat, mipmapped
  FullscreenTriangle fullscreen;
};

// Axis-aligned box against the view frustum's side and near planes.
bool box_visible(const glm::mat4& view_proj, const glm::vec3& lo, const glm::vec3& hi);

}  // namespace downpour::render
