// The lamps that light a frame (issue: light and relief), on the CPU: each vehicle's headlights,
// tail, brake, indicator and reversing lamps from its resolved state (sim/lights.hpp), and the
// street lights near the camera; then binned into screen tiles (forward+), so that a pixel's
// shader loops over its tile's lights only. Photometric: luminous intensity in candela per
// colour channel; the shader turns lux into its radiance with the frame's exposure. No GL.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include "server/render/cpu/shader_interface.hpp"
#include "server/sim/lights.hpp"
#include "server/sim/simulation.hpp"

namespace downpour::render {

enum class LampKind : std::uint8_t { kHeadlight, kTail, kBrake, kIndicator, kReverse, kStreet };

struct Light {
  glm::vec3 position{0.0f};      // world
  glm::vec3 direction{0.0f};     // world, unit: the beam's axis (a point lamp: any, cones at -1)
  glm::vec3 intensity_cd{0.0f};  // on the axis, per channel
  float cos_inner = -1.0f;       // full intensity within this cone,
  float cos_outer = -1.0f;       // none beyond this one
  float range_m = 0.0f;          // where its illuminance falls to LightSetConfig::cutoff_lux
  float ground_z = 0.0f;         // the height of the ground under it (its light's receiving plane)
  bool low_beam = false;         // a dipped beam: cut off above a line, raised on the nearside
  LampKind kind = LampKind::kHeadlight;
  std::int32_t vehicle = -1;  // -1 the ego car, else its index in the scene's traffic
};

struct LightSetConfig {
  // A passenger car's lamps (the ego car's shape: rear bumper 0.95 m behind the rear axle, front
  // bumper 3.65 m ahead; scaled to a traffic vehicle's size).
  glm::vec3 headlamp_m{3.6f, 0.62f, 0.7f};  // vehicle frame, the left one (y mirrored)
  glm::vec3 tail_lamp_m{-0.95f, 0.7f, 0.78f};
  // Low beam: 15,000 cd on the axis, aimed 1 degree down, 10 degrees to full, 30 to none (a
  // dipped beam's hot spot and spread, without its cut-off's asymmetry). High beam: 50,000 cd,
  // level, 6 and 20 degrees.
  float low_beam_cd = 15000.0f;
  float low_beam_down_deg = 1.0f;
  float low_beam_inner_deg = 10.0f;
  float low_beam_outer_deg = 30.0f;
  float high_beam_cd = 50000.0f;
  float high_beam_inner_deg = 6.0f;
  float high_beam_outer_deg = 20.0f;
  // Rear and side lamps (ECE R7, R6, R23: tail 4 cd, stop 60, indicator 200, reversing 150).
  float tail_cd = 4.0f;
  float brake_cd = 60.0f;
  float indicator_cd = 200.0f;
  float reverse_cd = 150.0f;
  float rear_lamp_outer_deg = 80.0f;  // they shine backwards, widely
  // Street lights: a road luminaire's wide flat beam, 3,000 cd out to 65 degrees from straight
  // down and none beyond 80 (37 lux under the lamp, 9 m up; 7 halfway between two, as lit roads
  // have); the nearest max_street within street_within_m of the camera.
  float street_cd = 3000.0f;
  float street_inner_deg = 65.0f;
  float street_outer_deg = 80.0f;
  int max_street = 20;
  float street_within_m = 250.0f;
  float cutoff_lux = 1.0f;  // a light's range: where it gives this much
};

// A vehicle's lamps as drawn: the scene's, whose automatic headlights the simulation resolves
// (sim/lights.hpp), resolved here too for a scene made without it (automatic: low beams when
// automatic_headlights_on; the brake lamps as given).
sim::VehicleLights shown_lights(const sim::VehicleLights& lights, const sim::Weather& weather);

// The frame's lights: the ego car's and the traffic's lamps that are lit at the scene's time, and
// the street lights (when lit) nearest to the camera.
std::vector<Light> build_lights(const sim::SceneState& scene,
                                const std::vector<sim::StreetLight>& street,
                                const glm::vec3& camera_m, const LightSetConfig& config = {});

// The lamps as the shaders read them (shader_interface.hpp's LampBlock): the ego car's headlights
// first (those that vehicle.frag evaluates per pixel), then every other lamp that lights its
// surroundings, those ahead of the camera (along `camera_forward`) nearest first, then those
// behind it (the wet road's glints take the first few after the ego car's), up to kMaxLamps. Tail
// lamps light nothing worth a shader's loop (4 cd): they show as lamps on the cars (vehicle.frag),
// not as lights.
struct PackedLamps {
  int ego = 0;    // the ego car's headlights, first
  int count = 0;  // all packed
  // Per packed lamp, the box (x0, y0, x1, y1; world m) of the ground it gives more than
  // kGroundCutLux (lamp_footprint): what the lamp map draws of it.
  std::vector<glm::vec4> ground_boxes;
};
// Below this a lamp's light on the ground is left out (the lamp map draws E - kGroundCutLux), so
// that each lamp draws only its footprint: 1 lux shows at night as 1/150 of white on asphalt.
inline constexpr float kGroundCutLux = 1.0f;
// A dipped beam's cut-off (right-hand traffic), for a unit direction from the lamp whose component
// to the beam's right is `right` and whose upward one is `up`: 1 under the line (0.6 degrees below
// the horizon towards the oncoming lanes, rising at 15 degrees on the nearside), 0 over it,
// smoothed over +-0.006; as common.glsl's lamp_lux.
inline float dipped_cut(float right, float up) {
  const float limit = -0.0105f + 0.268f * std::max(right, 0.0f);
  const float u = std::clamp((limit + 0.006f - up) / 0.012f, 0.0f, 1.0f);
  return u * u * (3.0f - 2.0f * u);
}
// What share of the light on a water drop it sends on at a scattering angle of cosine c, roughly:
// most forwards (an oncoming lamp's halo), some back (a beam from behind the eye), little
// sideways (a street lamp overhead); as common.glsl's lamps_scattered.
inline float drop_phase(float c) {
  const float fwd = std::max(c, 0.0f), back = std::max(-c, 0.0f);
  const float f2 = fwd * fwd, f4 = f2 * f2;
  return 0.06f + 0.3f * back * back + 2.0f * f4 * f4;
}

// The share of a lamp's intensity on its axis that it sends along the unit direction `dir`: its
// cones, and a dipped beam's cut-off, above which it leaves `stray` of it.
float beam_towards(const Light& light, const glm::vec3& dir, float stray = 0.0f);
// A lamp's illuminance (lux, the green channel) on its ground plane at xy, as the shaders' lamp_lux
// gives it on an upward surface.
float ground_lux(const Light& light, const glm::vec2& xy);
// The box around the ground where the lamp gives more than cut_lux: its illuminance sampled along
// 32 azimuths out to where no lamp of its intensity and height could give that much (an upward
// surface at distance d under a lamp h above gets at most I h / d^3). Empty (x0 > x1) if none.
glm::vec4 lamp_footprint(const Light& light, float cut_lux);
PackedLamps pack_lamps(const std::vector<Light>& lights, const glm::vec3& camera_m,
                       const glm::vec3& camera_forward, LampBlock& out);

// Screen tiles with the lights that may reach what they show: each light's sphere of influence
// (its position and range) against the view's frustum, its screen rectangle from its bounding
// box's corners (every tile when the box reaches behind the camera's plane).
struct LightTiles {
  int tile_px = 16;
  int tiles_x = 0;
  int tiles_y = 0;
  std::vector<std::uint32_t> first;   // per tile (rows bottom-up): the first index in `lights`
  std::vector<std::uint32_t> count;   // and how many
  std::vector<std::uint32_t> lights;  // indices into the frame's lights
  std::uint32_t max_per_tile() const;
  double mean_per_tile() const;
};
LightTiles bin_lights(const std::vector<Light>& lights, const glm::mat4& view_proj, int width,
                      int height, int tile_px = 16);

}  // namespace downpour::render
