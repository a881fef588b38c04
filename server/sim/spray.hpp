// Spray from tires and puddle splashes (seed 003, section 4, with the physics it leaves out): the
// water every vehicle's tires throw up from the wet road, as parcels of droplets that fly, drag in
// the air and the vehicles' wakes, land, and hit the ego car's windshield.
//
// Sources. Each tire of the ego car and of every traffic vehicle throws water from the road cell
// under it. The tread carries a share of the cell's standing film and a little of the water in the
// texture; the share grows with speed as v^2 / (v^2 + v0^2) (the tread's water leaves when the
// wheel's centripetal acceleration beats its hold). A parcel is born on the tire's arc behind the
// contact patch, at an angle from straight down drawn from a density that peaks at `peak_deg`; the
// mudguard blocks the arc above `mudguard_deg`, and what it blocks stays on the road. A parcel
// leaves with the rim's velocity there. Its droplets' size follows the paper's table 1 by the
// cell's state: Dry nothing, Wet small, Drench medium, Puddle large. Every tire also sheds mist, a
// tenth of the water as droplets of `diameter_mm[kMist]` that follow the air.
//
// Puddle splash. A tire in a puddle pushes a sheet of water aside: directions at theta from the
// direction of travel drawn from f(theta) = sin(2 theta) over 0-90 degrees, to both sides, rising
// at 10-35 degrees; the amount is a share of the standing water the tire sweeps, the speed a share
// of the tire's that grows with the depth. Splashes are large droplets.
//
// Flight. Gravity, and drag toward the air's velocity with the drag of a sphere of the kind's
// droplet size (Schiller-Naumann), integrated exactly over each step for the drag's time
// constant. The air is the wind plus the wake of the vehicle that threw the parcel: behind it the
// air is dragged along at up to `wake_fraction` of its velocity, fading over `wake_heights` of
// its height, and lifted near its back (so that spray hangs behind a truck at its height), with
// eddies whose strength follows the wake's, which mix its spray across its width (the drag
// decides how much a droplet follows them: mist all, large drops little). Large droplets that
// land give their water back to the road cell they land on (table 1's last column); smaller ones
// are lost to the road as the paper has it (they would only wet it again). Mist expires after
// `mist_life_s`.
//
// The glass. A parcel that crosses the ego car's windshield leaves a share of its water there (the
// rest flows around with the air: mist mostly does) as drops of `glass_drop_mg` (at most 16 of
// them, larger for a parcel that holds more) spread over the parcel's size; one that meets the
// rest of the ego car's body is gone.
//
// Vehicles farther than `max_range_m` from the ego car, or not on their wheels, throw nothing.
// Bounded: at most `max_particles` parcels; when full, the oldest go first. Deterministic: one
// random stream of the session's seed, sources and parcels in a fixed order. No GL.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "server/sim/random.hpp"
#include "server/sim/types.hpp"
#include "server/sim/windshield.hpp"

namespace downpour::sim {

class RoadWater;

// Droplet sizes (table 1): mist from every tire, small from a wet road, medium from a drenched
// one, large from puddles (tire spray and splash).
enum class SprayKind : std::uint8_t { kMist, kSmall, kMedium, kLarge };
inline constexpr int kSprayKinds = 4;

struct SprayConfig {
  std::uint32_t max_particles = 20000;
  double step_s = 1.0 / 60.0;  // the spray's own fixed step, on the simulation's sub-steps
  // Droplet diameters of each kind (drag, and what a glass hit leaves), mm.
  std::array<double, kSprayKinds> diameter_mm{0.05, 0.25, 0.7, 2.0};
  // A parcel's drawn size: the radius it is born with and how fast it spreads, m and m/s.
  std::array<double, kSprayKinds> radius_m{0.2, 0.08, 0.1, 0.12};
  std::array<double, kSprayKinds> spread_mps{0.30, 0.15, 0.12, 0.08};
  // The share of a parcel's water that stays on the windshield when it crosses it.
  std::array<double, kSprayKinds> glass_capture{0.3, 0.7, 0.9, 1.0};

  // The tires: a passenger car's, scaled with the vehicle's size (a truck's are larger).
  double tire_radius_m = 0.32;
  double tire_width_m = 0.21;
  double min_speed_mps = 1.0;  // slower tires throw nothing
  // The tread's share of the standing film and of the texture's water it throws at full speed,
  // and the speed at which it throws half of that (v0).
  double film_share = 0.3;
  double texture_share = 0.02;
  double throw_speed_mps = 10.0;
  double mist_share = 0.1;     // of the tire's water, as mist
  double splash_share = 0.5;   // of the standing water a tire in a puddle sweeps
  double peak_deg = 25.0;      // the birth density's peak, from straight down, behind the patch
  double mudguard_deg = 75.0;  // above this the mudguard blocks the arc
  // Parcels per tire per second at full flow (1 - exp(-flow / flow_ref)).
  double tire_parcels_per_s = 300.0;
  double mist_parcels_per_s = 200.0;
  double splash_parcels_per_s = 1200.0;
  double flow_ref_m3_s = 2e-4;

  // The wake: air dragged behind a vehicle at up to wake_fraction of its velocity, fading over
  // wake_heights of its height behind it; lifted near its back at up to upwash_fraction.
  double wake_fraction = 0.5;
  double wake_heights = 5.0;
  double upwash_fraction = 0.12;
  // Eddies: the air's velocity wanders about its mean (an Ornstein-Uhlenbeck process per parcel
  // with this correlation time), by turbulence_mps in still air and by wake_turbulence of the
  // vehicle's speed in its wake, so that a wake mixes its spray across its width.
  double turbulence_mps = 0.5;
  double wake_turbulence = 0.08;
  double eddy_s = 0.2;

  double mist_life_s = 4.0;
  double max_life_s = 8.0;
  double max_range_m = 250.0;  // farther from the ego car a parcel is let go
  double glass_drop_mg = 4.0;  // a glass hit leaves drops of this, up to 16 (then larger ones)
  // Body or spray (seed 001): a liquid parcel with this many others this near is in a body.
  double neighbour_radius_m = 0.2;
  int body_neighbours = 8;
  // A vehicle's body stops the spray that meets it (all but its own) and gets wet: the water it
  // caught wets it fully as a film of wet_film_mm over its whole surface, and runs off and dries
  // with this time constant.
  double wet_film_mm = 0.02;
  double body_dry_s = 40.0;
};

// What throws spray: the ego car (key 0) and each traffic vehicle (key id + 1), posed as in the
// contract (the ground under the rear axle), its size as the renderer scales the car to it.
struct SpraySource {
  std::uint32_t key = 0;
  VehicleState state;
  glm::dvec3 size_m{4.5, 1.8, 1.47};
  VehicleClass vehicle_class = VehicleClass::kCar;  // where its back is (its wake starts there)
};

struct SprayParticle {
  glm::dvec3 position_m{0.0};  // world
  glm::dvec3 velocity_mps{0.0};
  glm::vec3 eddy_mps{0.0f};  // the air's deviation from its mean where it is
  double volume_m3 = 0.0;    // the water it carries
  float age_s = 0.0f;
  std::uint32_t source = 0;  // the key of the vehicle that threw it
  SprayKind kind = SprayKind::kSmall;
  bool splash = false;      // from a puddle splash (else from the tire)
  float gathered_m = 0.0f;  // the radius of its water gathered into one sphere (set at its birth)
};

// What the spray asks of the road's water: the state and depth under a tire, and water taken and
// given back (m^3; each returns how much it moved).
class SprayGround {
 public:
  virtual ~SprayGround() = default;
  struct Probe {
    double water_m = 0.0;     // all the water there (texture and standing)
    double standing_m = 0.0;  // the part standing above the texture
    RoadState state = RoadState::kDry;
    bool beyond = false;  // outside the modelled road: the water is not taken from anywhere
  };
  virtual Probe probe(glm::dvec2 xy) const = 0;
  virtual double take(glm::dvec2 xy, double volume_m3) = 0;
  virtual double give(glm::dvec2 xy, double volume_m3) = 0;
};

// The road's water model as the spray's ground. Beyond its windows (a vehicle far ahead), the
// tires throw from the windows' mean water, taken from nowhere (booked as `beyond_m3`).
class RoadWaterGround final : public SprayGround {
 public:
  explicit RoadWaterGround(RoadWater& road) : road_(road) {}
  Probe probe(glm::dvec2 xy) const override;
  double take(glm::dvec2 xy, double volume_m3) override;
  double give(glm::dvec2 xy, double volume_m3) override;
  // The windows' mean water (from the last image of them), for the road beyond them.
  void set_mean(double water_m, double standing_m) {
    mean_water_m_ = water_m;
    mean_standing_m_ = standing_m;
  }

 private:
  RoadWater& road_;
  double mean_water_m_ = 0.0, mean_standing_m_ = 0.0;
};

// Where the water thrown went (m^3): taken + beyond = airborne + returned + landed + on_glass +
// on_body + dispersed + dropped.
struct SprayLedger {
  double taken_m3 = 0.0;      // from the road's cells
  double beyond_m3 = 0.0;     // thrown beyond the road's windows (not in its ledger)
  double returned_m3 = 0.0;   // large droplets that landed back in a cell
  double landed_m3 = 0.0;     // smaller droplets that landed (and large ones off the windows)
  double on_glass_m3 = 0.0;   // left on the ego car's windshield
  double on_body_m3 = 0.0;    // on a vehicle's body: the rest of the ego car, the traffic
  double dispersed_m3 = 0.0;  // mist that expired, and what flowed around the glass
  double dropped_m3 = 0.0;    // parcels let go: the budget, their age, their range
};

// The parcels for the renderer (seed 001's input), positions relative to `origin_m` (the ego
// car's reference point when taken). Each parcel is a cloud of droplets of its kind's size spread
// over radius_m: it is drawn as a haze of that size whose optical depth through its centre is
// `haze_depth` (geometric optics: extinction twice the droplets' cross-section per volume), and,
// but for mist, as a sphere of liquid of `liquid_radius_m` (its water gathered into one sphere).
// `body`: the parcel has at least body_neighbours others within neighbour_radius_m (a spatial
// hash): part of a liquid body (a splash's sheet), drawn at least a third of that radius so that
// the sheet's parcels overlap; else lone spray.
struct SprayImage {
  glm::dvec3 origin_m{0.0};
  struct Point {
    float x, y, z, radius_m;
    float liquid_radius_m, haze_depth;
    SprayKind kind;
    bool splash;
    bool body;
  };
  std::vector<Point> points;
  std::array<std::uint32_t, kSprayKinds> counts{};
};

class Spray {
 public:
  Spray(std::uint64_t seed, SprayConfig config = {});

  // Advances by one fixed step (config().step_s). sources[0] must be the ego car when `glass` is
  // given: parcels that cross its windshield call glass_hit(uv_mm, mass_mg), which says whether
  // the drop stayed on the glass.
  using GlassHit = std::function<bool(glm::dvec2, double)>;
  void step(const std::vector<SpraySource>& sources, glm::dvec3 wind_mps, SprayGround& ground,
            const GlassConfig* glass = nullptr, const GlassHit& glass_hit = {});

  const std::vector<SprayParticle>& particles() const { return particles_; }
  const SprayLedger& ledger() const { return ledger_; }
  // How wet the spray has made the body of the vehicle with this key (0 dry to 1), its size as
  // its source gave it.
  double body_wetness(std::uint32_t key, glm::dvec3 size_m) const;
  double airborne_m3() const;
  const SprayConfig& config() const { return config_; }
  void image(glm::dvec3 origin_m, SprayImage& out);
  double radius_m(const SprayParticle& p) const {
    const int k = static_cast<int>(p.kind);
    return config_.radius_m[k] + config_.spread_mps[k] * p.age_s;
  }

 private:
  struct Pose;
  void emit(const Pose& source, SprayGround& ground);
  void classify(SprayImage& out);
  // The air dragged along by a vehicle at p, and how strong its wake is there (0-1).
  glm::dvec3 wake(const Pose& source, glm::dvec3 p, double* strength) const;

  // The drag over one step by relative speed (up to kDragSteps * kDragSpeedStep m/s): its rate
  // (1/s), what is left of the velocity toward the air (decay), and the time the difference
  // travels for (gone = (1 - decay) / rate).
  struct Drag {
    double rate = 0.0, decay = 0.0, gone = 0.0;
  };
  static constexpr int kDragSteps = 400;
  static constexpr double kDragSpeedStep = 0.25;
  Drag drag_at(int kind, double speed) const;

  // The bodies that stop spray this step, and a grid over the ego car's range that finds them.
  struct Target {
    std::uint32_t key;
    glm::dvec2 centre;  // its footprint's centre (world), and the square of its reach
    double reach2;
    glm::dvec3 position;
    glm::dmat3 to_vehicle;  // world to vehicle
    glm::dvec3 lo, hi;      // its box in its own frame
    double wet_m3;          // what it caught this step
  };
  void find_targets(const std::vector<SpraySource>& sources, std::size_t first);
  Target* target_at(glm::dvec3 p, std::uint32_t source);
  void wet_bodies();

  SprayConfig config_;
  std::vector<Target> targets_;
  glm::dvec2 grid_origin_{0.0};
  std::vector<std::int32_t> grid_head_;    // per cell, its first entry (-1: none)
  std::vector<std::int32_t> grid_target_;  // per entry, its target and the next entry in its cell
  std::vector<std::int32_t> grid_next_;
  // classify()'s buffers, kept from image to image (no allocation once they have grown).
  struct Classified {
    struct Entry {
      float x, y, z;
      glm::ivec3 cell;
      std::uint32_t index;  // in the image's points
    };
    std::vector<glm::ivec3> cell;
    std::vector<std::uint32_t> bucket, start, fill;
    std::vector<Entry> sorted;
  };
  Classified classified_;
  // Each body's caught water (m^3) by key, sorted.
  std::vector<std::pair<std::uint32_t, double>> body_water_;
  std::array<std::array<Drag, kDragSteps + 1>, kSprayKinds> drag_{};
  RandomStream random_;
  std::vector<SprayParticle> particles_;  // oldest first
  SprayLedger ledger_;
};

}  // namespace downpour::sim
