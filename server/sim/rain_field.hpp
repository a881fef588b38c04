// Rain in the air (seed 004, with the physics of Marshall-Palmer and Atlas): the falling drops
// near the car, as the renderer draws them as streaks, and the extinction that hides the rest.
//
// The field holds the distribution's large drops, those of at least `drawn_min_diameter_mm(R)`,
// inside a box that travels with the car: `length_m` ahead from `behind_m` behind the eye,
// `width_m` across, from the ground up `height_m`. Their number is the box's volume times the
// Marshall-Palmer number density above that size, so it follows the rain rate
// (Weather::rain_streak_count overrides it). Each drop keeps the size it was born with and falls at
// the Atlas terminal speed of that size, tilted by Weather::rain_angle_deg (about the car's forward
// axis, as the paper's control tilts the rain on screen) and drifting with the wind. A drop that
// reaches the ground restarts at the top of the box at a new place; drops the car leaves behind
// wrap to the front, so the drops stay where they are in the world while in the box. A drop that
// lands on the road, the car's bonnet, boot or roof leaves a splash there: a crown of droplets for
// kSplashLifeS, so that the splashes' rate is the large drops' flux and follows the rain rate. The
// field steps at a fixed rate of its own, on the simulation's sub-steps: the same seed and inputs
// give the same drops. No GL.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "server/sim/drop_physics.hpp"
#include "server/sim/random.hpp"
#include "server/sim/types.hpp"

namespace downpour::sim {

// Marshall-Palmer: N(D) = N0 exp(-L D), N0 = 8000 m^-3 mm^-1, L = 4.1 R^-0.21 mm^-1.
inline constexpr double kMarshallPalmerN0 = 8000.0;
double marshall_palmer_slope_per_mm(double rain_mm_h);
// Drops per cubic metre with a diameter of at least d_min_mm; 0 without rain.
double marshall_palmer_density(double rain_mm_h, double d_min_mm);
// Each drop falls at terminal_speed_mps of its size (drop_physics.hpp, Atlas et al. 1973).
// Optical extinction of the rain, per metre: twice the drops' cross-section per volume (geometric
// optics), over the whole Marshall-Palmer distribution: pi N0 / L^3 (with D in mm, 1e-6 m^2/mm^2).
// It grows as R^0.63: 0.56 per km at 2 mm/h, 1.55 at 10, 4.2 at 50.
double rain_extinction_per_m(double rain_mm_h);
// The meteorological visibility for an extinction (Koschmieder, 2% contrast): 3.912 / sigma.
double visibility_m(double extinction_per_m);

// Drops per square metre per second of a diameter in [d_min_mm, d_max_mm] that reach the ground:
// the Marshall-Palmer density times the Atlas terminal speed, integrated over the sizes (those
// above d_max_mm counted at d_max_mm, as the field clamps them).
double marshall_palmer_flux(double rain_mm_h, double d_min_mm, double d_max_mm);

inline constexpr std::uint32_t kMaxRainDrops = 80000;
// A splash's crown rises and falls back in this time (a few tens of milliseconds for millimetre
// drops on a wet surface); the field keeps the most recent splashes, up to this many.
inline constexpr double kSplashLifeS = 0.06;
inline constexpr std::size_t kMaxRainSplashes = 16384;

struct RainFieldConfig {
  // The smallest drop drawn from `full_tail_mm_h` (moderate rain) up; smaller drops make faint
  // streaks, and are in the extinction. In lighter rain the drawn drops are the same share of the
  // distribution as at that rate: Marshall-Palmer's sizes scale as 1/L, so the smallest drawn is
  // min_diameter_mm (R / full_tail_mm_h)^0.21 (2.1 mm at 2 mm/h), and light rain shows sparse
  // streaks of smaller drops (about 2,400 at 2 mm/h, against 500 with 2.5 mm at every rate, and
  // 9,000 at 10 mm/h).
  // Never under smallest_drawn_mm (below about 0.06 mm/h), so a trace of rain draws next to none.
  double min_diameter_mm = 2.5;
  double full_tail_mm_h = 5.0;
  double smallest_drawn_mm = 1.0;
  double max_diameter_mm = 6.0;  // larger ones break up as they fall
  double behind_m = 2.0;         // the box's back, behind the eye
  double length_m = 24.0;        // along the car's heading
  double width_m = 12.0;
  double height_m = 5.5;  // above the ground under the car
  // The field's own fixed step. A drop falls straight between steps, so a longer step moves it
  // the same; the renderer carries the drops on to a frame's time. (1/60 s cost the step thread
  // 0.3 ms a frame more: 33,000 drops at 25 mm/h, twice a frame.)
  double step_s = 1.0 / 30.0;
  double eye_height_m = 1.2;   // the box is centred on the driver's eye, not the axle
  double eye_forward_m = 1.3;  // from the pose's reference point
  double volume_m3() const { return length_m * width_m * height_m; }
  double drawn_min_diameter_mm(double rain_mm_h) const;
};

struct RainDrop {
  glm::dvec3 position_m{0.0};  // world
  double diameter_mm = 0.0;
  double speed_mps = 0.0;  // terminal speed of its size
};

// Where and when a drop landed.
struct RainSplash {
  glm::dvec3 position_m{0.0};  // world on the road; the vehicle frame on the car
  double time_s = 0.0;         // when it landed
  float diameter_mm = 0.0f;    // the drop's
  bool on_car = false;
};

// A splash as the renderer draws it.
struct SplashState {
  glm::vec3 position{0.0f};  // on the road: relative to RainState::origin_m; on the car: the
                             // vehicle frame (it moves with the car)
  float age_s = 0.0f;        // at RainState::time_s, in [0, kSplashLifeS]
  float diameter_mm = 0.0f;
  bool on_car = false;
};

// What the renderer draws: the drops at `time_s` (positions relative to `origin_m`, in float),
// and how they move, for a streak that is their motion during the exposure relative to the camera.
struct RainState {
  double time_s = 0.0;                      // when the drops were at these positions
  glm::dvec3 origin_m{0.0};                 // world, the box's centre; the drops are relative to it
  glm::vec3 box_forward{1.0f, 0.0f, 0.0f};  // world, unit: the box's axes and half sizes
  glm::vec3 box_left{0.0f, 1.0f, 0.0f};
  glm::vec3 box_half_m{0.0f};                   // along, across, up
  glm::vec3 fall_direction{0.0f, 0.0f, -1.0f};  // world, unit: the fall without wind
  glm::vec3 wind_mps{0.0f};                     // world: the drift every drop shares
  std::vector<glm::vec4> drops;       // xyz position relative to origin_m (m), w diameter (mm)
  std::vector<SplashState> splashes;  // those younger than kSplashLifeS
  double extinction_per_m = 0.0;      // the rain's (fog adds its own)
};

class RainField {
 public:
  RainField(std::uint64_t seed, RainFieldConfig config = {});

  // The number of drops the box holds for this weather (the override, or Marshall-Palmer).
  std::uint32_t target_count(const Weather& weather) const;
  // Advances by whole steps of config().step_s as the sub-steps add up; the weather and the car's
  // pose are those of the sub-step.
  void advance(double dt_s, double time_s, const Weather& weather, const VehicleState& vehicle);
  void publish(RainState* out) const;

  const std::vector<RainDrop>& drops() const { return drops_; }
  const RainFieldConfig& config() const { return config_; }
  // Splashes since the field began, on the road and on the car (their rate is the tests').
  std::uint64_t road_splashes() const { return road_splashes_; }
  std::uint64_t car_splashes() const { return car_splashes_; }
  // The fall direction (world, unit) for the weather and the car's heading.
  static glm::dvec3 fall_direction(const Weather& weather, const VehicleState& vehicle);

 private:
  struct Box {
    glm::dvec3 centre;   // world, at mid height
    glm::dvec3 forward;  // unit, horizontal
    glm::dvec3 left;     // unit, horizontal
    double ground_z;
  };
  Box box_for(const VehicleState& vehicle) const;
  RainDrop born(const Box& box, double rain_mm_h, bool anywhere_in_height);
  void step(double dt_s, double end_s, const Weather& weather, const VehicleState& vehicle);
  // Whether a drop that moved from `before` to `after` (world) during the step ending at end_s
  // hit the car; if so, records its splash where it came through the top of the hull or the roof.
  bool hit_car(const glm::dvec3& before, const glm::dvec3& after, double dt_s, double end_s,
               double diameter_mm, const VehicleState& vehicle, const Box& box);
  void splash(const RainSplash& s);

  RainFieldConfig config_;
  RandomStream random_;
  std::vector<RainDrop> drops_;
  std::vector<RainSplash> splashes_;  // a ring of the latest kMaxRainSplashes
  std::size_t next_splash_ = 0;
  std::uint64_t road_splashes_ = 0, car_splashes_ = 0;
  double carry_s_ = 0.0;
  double time_s_ = 0.0;
  Weather weather_;
  VehicleState vehicle_;
};

}  // namespace downpour::sim
