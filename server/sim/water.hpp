// Water on the windshield (seed 000, TECHNIQUES.md section 1): a mesh model for drops away from
// the wipers and a particle model around each blade, with the switching between them, rain
// arriving from physics and airflow at speed. Glass space, millimetres; masses in milligrams
// (= cubic millimetres of water). Deterministic: fixed steps and the session's seed.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "server/sim/random.hpp"
#include "server/sim/windshield.hpp"

namespace downpour::sim {

// Drops on the glass are spherical caps meeting it at this angle (clean automotive glass: 30 to
// 50 degrees; the renderer draws its lenses with the same angle).
constexpr double kContactAngleDeg = 40.0;

// Radius (mm) of the contact circle of a drop of this mass, a spherical cap at kContactAngleDeg.
double drop_radius_mm(double mass_mg);
double drop_mass_mg(double radius_mm);
// Its cross-section facing air that flows along the glass, mm^2.
double drop_frontal_area_mm2(double radius_mm);

// Terminal fall speed (m/s) of a raindrop of diameter d (mm), Atlas et al. 1973.
double terminal_speed_mps(double diameter_mm);

struct WaterInputs {
  double rain_rate_mm_h = 0.0;
  // Rain's velocity relative to the glass, vehicle frame, without the fall: wind minus the car's
  // own velocity (m/s). The fall (terminal speed) is added per drop size.
  glm::dvec3 air_velocity_mps{0.0};
  std::array<BladePose, 2> blades_before;  // at the start of the step
  std::array<BladePose, 2> blades_after;   // at its end
};

// Where the water went, mg: arrived = on the glass + wiped_off + drained + evaporated.
struct WaterLedger {
  double arrived = 0.0;     // raindrops that hit the glass (and water placed by tests)
  double wiped_off = 0.0;   // pushed past the glass edge by a blade
  double drained = 0.0;     // ran off the edge by itself
  double evaporated = 0.0;  // trail drops that shrank away
};

class WaterSim {
 public:
  struct Drop {  // mesh model
    glm::dvec2 pos{0.0};
    double mass = 0.0;
    double radius = 0.0;            // cached drop_radius_mm(mass)
    double travel = 0.0;            // distance owed from this step's motion, mm
    glm::dvec2 heading{0.0, -1.0};  // direction of the last move
    bool moving = false;
    bool trail = false;
    double age = 0.0;          // trail drops: seconds since left behind
    double trail_mass0 = 0.0;  // trail drops: mass and radius when left behind
    double trail_radius0 = 0.0;
    int subs = 0;  // impact sub-metaballs still merging
    double sub_age = 0.0;
    std::array<glm::vec2, 3> sub_dir{};  // their unit directions from the main metaball
    bool alive = false;
  };
  struct Particle {  // particle model
    glm::dvec2 pos{0.0};
    double mass = 0.0;
    double held_s = 0.0;  // time suspended outside every blade's region
  };

  WaterSim(const WindshieldConfig& config, std::uint64_t seed);

  void step(double dt_s, const WaterInputs& inputs);
  void publish(WindshieldState& out) const;

  const WaterLedger& ledger() const { return ledger_; }
  double mass_on_glass() const;
  std::uint32_t drop_count() const { return drop_count_; }
  const std::vector<Drop>& drops() const { return drops_; }  // alive ones have alive = true
  const std::vector<Particle>& particles() const { return particles_; }
  const WindshieldConfig& config() const { return config_; }

  // Tests and tools: place water directly (counted as arrived). add_drop fuses into an occupied
  // cell; returns false outside the glass.
  bool add_drop(glm::dvec2 pos_mm, double mass_mg, bool with_sub_metaballs = false);
  void add_particle(glm::dvec2 pos_mm, double mass_mg);
  int drop_at(glm::dvec2 pos_mm) const;  // index into drops(), -1 if none
  double particle_mass() const { return particle_mass_; }
  // The fixed random affinity of the cell containing pos (glass irregularity).
  double affinity_at(glm::dvec2 pos_mm) const;
  // Would a drop of this radius flow under these inputs? (gravity + airflow against pinning)
  glm::dvec2 drive_per_pin(double radius_mm, const WaterInputs& inputs) const;

 private:
  int cell_index(glm::dvec2 pos) const;  // -1 outside the grid
  bool on_glass(glm::dvec2 pos) const { return config_.glass.contains(pos); }
  int new_drop(glm::dvec2 pos, double mass);
  void remove_drop(int i);
  void set_mass(Drop& d, double mass);
  void fuse_into(int target, double mass);
  int coalesce(int i);
  void place_drop(glm::dvec2 pos, double mass, bool with_sub_metaballs);

  void rain(double dt, const WaterInputs& in);
  void move_drops(double dt, const WaterInputs& in);
  void move_drop(int i, double dt);
  void sweep_blades(const WaterInputs& in);
  void repel_particles();
  void release_particles(double dt, const WaterInputs& in);
  bool in_any_region(glm::dvec2 pos, const std::array<BladePose, 2>& blades) const;
  bool suspended(glm::dvec2 pos) const;

  WindshieldConfig config_;
  RandomStream rain_random_;
  RandomStream move_random_;
  RandomStream blade_random_;
  int cells_u_ = 0, cells_v_ = 0;
  std::vector<float> affinity_;
  std::vector<std::int32_t> cell_drop_;  // drop index per cell, -1 empty
  std::vector<Drop> drops_;
  std::vector<std::int32_t> free_drops_;
  std::uint32_t drop_count_ = 0;
  std::vector<Particle> particles_;
  double particle_mass_ = 0.0;
  // Water each blade has gathered from drops but not yet a whole particle's worth, mg (counted
  // as on the glass: it rides on the blade's edge).
  std::array<double, 2> carried_{};
  double pin_per_mm_ = 0.0;  // pinning force per mm of radius, N/mm, from the critical radius
  glm::dvec2 gravity_{0.0};  // along the glass, m/s^2, in (u, v)
  glm::dvec2 air_{0.0};      // airflow along the glass at the drops, m/s, in (u, v)
  double air_spread_ = 0.0;  // its sideways part at the glass side edges, m/s
  std::array<BladePose, 2> blades_{};  // as of the last step
  WaterLedger ledger_;
  // Particle neighbour hash: bucket start offsets and the ids sorted by bucket.
  std::vector<std::uint32_t> hash_start_, hash_fill_;
  std::vector<std::uint32_t> hash_ids_;  // particle index, in bucket order
  std::vector<glm::vec2> hash_pos_;      // its position, in bucket order
  std::vector<glm::ivec2> hash_cell_;    // grid cell, in particle order
};

}  // namespace downpour::sim
