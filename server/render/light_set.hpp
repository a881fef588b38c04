// The lamps that light a frame (issue: light and relief), on the CPU: each vehicle's headlights,
// tail, brake, indicator and reversing lamps from its resolved state (sim/lights.hpp), and the
// street lights near the camera; then binned into screen tiles (forward+), so that a pixel's
// shader loops over its tile's lights only. Photometric: luminous intensity in candela per
// colour channel; the shader turns lux into its radiance with the frame's exposure. No GL.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

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
  // Street lights: 8,000 cd straight down, to none 75 degrees from it; the nearest max_street
  // within street_within_m of the camera.
  float street_cd = 8000.0f;
  float street_outer_deg = 75.0f;
  int max_street = 20;
  float street_within_m = 250.0f;
  float cutoff_lux = 1.0f;  // a light's range: where it gives this much
};

// The frame's lights: the ego car's and the traffic's lamps that are lit at the scene's time, and
// the street lights (when lit) nearest to the camera.
std::vector<Light> build_lights(const sim::SceneState& scene,
                                const std::vector<sim::StreetLight>& street,
                                const glm::vec3& camera_m, const LightSetConfig& config = {});

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
