// The mesh model of seed 000 (section 1.1): drops away from the wipers, one at most
// in each cell of a grid over the glass whose cells have a random affinity (dirt, scratches).
// A drop above the critical size flows under gravity and the airflow against its pinning, one
// cell at a time to one of three neighbours chosen by affinity, fusing with what it meets and
// leaving a trail of small drops that shrink away. Glass space, millimetres; masses in mg.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/vec2.hpp>

#include "server/sim/random.hpp"
#include "server/sim/windshield.hpp"

namespace downpour::sim {

class MeshModel {
 public:
  struct Drop {
    glm::dvec2 pos{0.0};
    double mass = 0.0;
    double radius = 0.0;            // cached drop_radius_mm(mass)
    double travel = 0.0;            // distance owed from this step's motion, mm
    glm::dvec2 heading{0.0, -1.0};  // direction of the last move
    bool moving = false;
    bool trail = false;
    int cells_since_trail = 0;  // a moving drop's cells since it last left a trail drop
    double age = 0.0;           // trail drops: seconds since left behind
    double trail_mass0 = 0.0;   // trail drops: mass and radius when left behind
    double trail_radius0 = 0.0;
    int subs = 0;  // impact sub-metaballs still merging
    double sub_age = 0.0;
    std::array<glm::vec2, 3> sub_dir{};  // their unit directions from the main metaball
    bool alive = false;
  };

  MeshModel(const WindshieldConfig& config, std::uint64_t seed);

  // Moves the drops by dt under gravity and `air` (the airflow along the glass at the drops, m/s,
  // in (u, v)), ages trails and impact sub-metaballs.
  void step(double dt, glm::dvec2 air);
  // Water arriving at pos: it fuses into the drop of that cell, or becomes a new drop (with
  // impact sub-metaballs whose directions come from sub_metaball_random, if given); then drops
  // that touch run together.
  void place(glm::dvec2 pos, double mass, RandomStream* sub_metaball_random);
  void remove(int i);
  // Is a drop at or above the critical size within the suspension search square around pos?
  bool holds_critical_drop_near(glm::dvec2 pos) const;

  const std::vector<Drop>& drops() const { return drops_; }  // alive ones have alive = true
  // The alive drops in the cells of the grid that the convex polygon `outline` reaches (its corners
  // in order, either way round), by index, ascending, into `out` (cleared first): every drop whose
  // centre lies in the polygon, and some beside it. It reads those cells, row by row, not every
  // drop: a blade's step reaches a few thousand cells of the glass's 280,000. (Every drop for a
  // polygon with a corner at no finite place.)
  void drops_within(std::span<const glm::dvec2> outline, std::vector<int>& out) const;
  // No alive drop's radius is larger (mm): the largest any drop has had.
  double radius_bound() const { return radius_bound_; }
  std::uint32_t count() const { return count_; }
  double mass() const;
  double drained() const { return drained_; }        // ran off the glass's edge, mg
  double evaporated() const { return evaporated_; }  // trail drops that shrank away, mg
  int drop_at(glm::dvec2 pos) const;                 // index into drops(), -1 if none
  double affinity_at(glm::dvec2 pos) const;
  // Drive over pinning of a drop of radius r (mm) under gravity and `air`: it flows where > 1.
  glm::dvec2 drive_per_pin(double radius_mm, glm::dvec2 air) const;

 private:
  int cell_index(glm::dvec2 pos) const;  // -1 outside the grid
  bool on_glass(glm::dvec2 pos) const { return config_.glass.contains(pos); }
  int new_drop(glm::dvec2 pos, double mass);
  void set_mass(Drop& d, double mass);
  void fuse_into(int target, double mass);
  int coalesce(int i);
  void move_drop(int i, double dt);

  WindshieldConfig config_;
  RandomStream move_random_;
  int cells_u_ = 0, cells_v_ = 0;
  std::vector<float> affinity_;
  std::vector<std::int32_t> cell_drop_;  // drop index per cell, -1 empty
  std::vector<Drop> drops_;
  std::vector<std::int32_t> free_drops_;
  std::uint32_t count_ = 0;
  double pin_per_mm_ = 0.0;  // pinning force per mm of radius, N/mm, from the critical radius
  glm::dvec2 gravity_{0.0};  // along the glass, m/s^2, in (u, v)
  glm::dvec2 air_{0.0};      // this step's airflow along the glass, m/s, in (u, v)
  double air_spread_ = 0.0;  // its sideways part at the glass side edges, m/s
  double drained_ = 0.0;
  double evaporated_ = 0.0;
  double radius_bound_ = 0.0;
};

}  // namespace downpour::sim
