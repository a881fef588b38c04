// What every pass sees of the frame it draws, the GL resources of the frame, and the resources the
// passes share for the renderer's life.
#pragma once

#include <array>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/mat4x4.hpp>

#include "server/render/cpu/atmosphere.hpp"
#include "server/render/cpu/camera.hpp"
#include "server/render/cpu/glass_view.hpp"
#include "server/render/gl/gl_objects.hpp"
#include "server/render/resource.hpp"
#include "server/sim/simulation.hpp"

namespace downpour::render {
namespace relief {
struct RoadReliefs;
}
struct Light;
struct World;

struct FrameContext {
  // The simulator's inputs for this frame: pose, weather, traffic, the time after the step. Its
  // `windshield` is not read here: the water may still be stepping on another thread.
  const sim::SceneState& scene;
  const sim::ViewSpec& spec;
  Camera camera;
  Atmosphere atmosphere;
  glm::mat4 vehicle_to_world{1.0f};
  GlassView glass;  // where the view meets the windshield, and how sharply it sees the glass
  // The state after this frame's step; waits for the step. Passes that declare
  // PassDecl::reads_step call it (through water()); rain() only on a session's first frame.
  std::function<const sim::SceneState&()> stepped;
  // Chunked geometry takes its level of detail as from this many times as far: a view's pixel
  // angle over that of COCKPIT at 720 rows (detail_distance_scale()), the geometry's levels'
  // distances being set for that. (The road reflection, at a quarter of the view's size, needs a
  // quarter of its view's detail; an environment face, as its texels' angle says.)
  float detail_distance_scale = 1.0f;
  // The frame's lamps (light_set.hpp), once the renderer has made them: for the passes that light
  // what the lamp map does not hold (the rain's drops).
  const std::vector<Light>* lights = nullptr;
  // Whether any lamp lights the frame (by day none is made: frame_lamps.cpp).
  bool has_lamps() const { return lights && !lights->empty(); }
  // What is drawn of the session's roads (world.hpp).
  const World* world = nullptr;
  // Where a face of the environment is drawn from a client's picture: the camera the picture was
  // taken from (the view's); null elsewhere (the frame's own camera is the picture's).
  const Camera* picture_camera = nullptr;
  // The camera a client's picture was taken from, wherever this frame draws.
  const Camera& picture_camera_or_own() const { return picture_camera ? *picture_camera : camera; }

  const sim::WindshieldState& water() const { return stepped().windshield; }
  // The rain: the inputs' (the last step's drops, which the rain layer moves on to the frame's
  // time), not the step's, so that the rain need not wait for the step; but before the first step
  // (no rain published yet: a session's first frame) the step's.
  const sim::RainState& rain() const {
    const bool published = !scene.rain.drops.empty() || scene.rain.time_s > 0.0;
    return published ? scene.rain : stepped().rain;
  }
};

// A program that lights with the lamps (common.glsl's lamp_ground, ego_headlights,
// lamps_scattered) is built twice: as is, and with NO_LAMPS, which compiles the lamps out for the
// frames that have none. Their code returns nothing without lamps, yet llvmpipe runs both sides
// of a branch, even one that every pixel takes alike: by day the lamp map's fetches cost the
// road, the terrain and the vehicles a tenth of their time. The builds' defines, by
// lamps_build().
inline const std::vector<std::string> kLampBuilds[2] = {{}, {"NO_LAMPS"}};
inline int lamps_build(const FrameContext& f) { return f.has_lamps() ? 0 : 1; }

// A texture the passes draw into or read, with its size.
struct TargetTexture {
  GLuint texture = 0;
  int width = 0;
  int height = 0;
};

// A target a pass of the frame drew into: its colour, its depth where it has one, its framebuffer.
struct FrameTarget {
  TargetTexture colour;
  TargetTexture depth;
  GLuint fbo = 0;
};

// The frame's resources (resource.hpp): the renderer binds the framebuffer a pass writes and the
// textures it reads before the pass runs.
struct FrameResources {
  GLuint view_fbo = 0;
  TargetTexture view_colour;
  TargetTexture view_depth;
  TargetTexture environment;  // the session's environment probe (a cube map: a face's size)
  glm::mat3 environment_from_world{1.0f};  // turns world directions into the probe's axes
  // Each transient (the glass layer, the road reflection, the spray layer) once the pass that
  // writes it has begun; empty before.
  std::array<FrameTarget, kResourceCount> transients{};
  // A client-background view's picture (RGBA8) and its depth (the view's reversed-Z, D32F; none
  // without one), once a pass reads them.
  TargetTexture client_colour;
  TargetTexture client_depth;
  const FrameTarget& transient(Resource r) const { return transients[static_cast<std::size_t>(r)]; }
};

// Resources made once and shared by the passes.
struct SharedResources {
  Texture noise;  // make_noise, repeat (the terrain's grain)
  // The asphalt's relief and the setts', two layers over one tile (shared_resources.cpp), repeat,
  // mipmapped.
  Texture ground_relief;
  FullscreenTriangle fullscreen;
  Texture horizon;  // relief::road_reliefs' horizon maps, RG16F, a layer per azimuth and relief
  int horizon_directions = 0;
  std::shared_ptr<const relief::RoadReliefs> reliefs;
};

// The shared resources made and bound to their units (shared_resources.cpp). Render thread.
std::unique_ptr<SharedResources> make_shared_resources();

// Axis-aligned box against the view frustum's side and near planes.
bool box_visible(const glm::mat4& view_proj, const glm::vec3& lo, const glm::vec3& hi);

// FrameContext::detail_distance_scale for pixels (or texels) pixel_rad wide: as many times as
// COCKPIT's at 720 rows (60 degrees), at least 1. A 640x360 COCKPIT takes its terrain's 40 m cells
// from 100 m on, where 1280x720 takes them from 200 m: the same pixels a cell.
float detail_distance_scale(double pixel_rad);

}  // namespace downpour::render
