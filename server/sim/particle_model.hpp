// The particle model of seed 000 (section 1.2): the water near the wipers as particles made
// equal, which never fuse as they move (only a blade's strip too deep for its region gathers its
// water into fewer: blade_sweep.cpp); where two overlap both move apart along the line of their
// centres by half the overlap, and further by the overlap times a penalty. Glass space,
// millimetres.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <glm/vec2.hpp>

#include "server/sim/windshield.hpp"

namespace downpour::sim {

class ParticleModel {
 public:
  struct Particle {
    glm::dvec2 pos{0.0};
    double mass = 0.0;
    double held_s = 0.0;  // time suspended outside every blade's region
  };

  explicit ParticleModel(const WaterConfig& config);

  void add(glm::dvec2 pos, double mass) { particles_.push_back({pos, mass, 0.0}); }
  // Pushes overlapping particles apart (a few passes, stopping once none overlap).
  void repel();
  // The blades' regions: each a rectangle as long as its blade and as wide as the blade plus
  // region_particle_diameters on each side. A blade of negative length has none. (Their
  // directions are worked out once, for all of a step's particles.)
  class Regions {
   public:
    Regions(const WaterConfig& config, const std::array<BladePose, 2>& blades);
    bool contain(glm::dvec2 pos) const;

   private:
    struct Region {
      glm::dvec2 pivot, along, across;  // along the blade, and its left normal
      double length, half_width;
    };
    std::array<Region, 2> regions_;
  };
  Regions regions(const std::array<BladePose, 2>& blades) const { return {config_, blades}; }

  std::vector<Particle>& particles() { return particles_; }
  const std::vector<Particle>& particles() const { return particles_; }
  double particle_mass() const { return particle_mass_; }  // a particle's as made, mg
  double mass() const;

 private:
  WaterConfig config_;
  std::vector<Particle> particles_;
  double particle_mass_ = 0.0;
  // Scratch for repel: cells and keys in particle order, ids sorted by key, and the sorted
  // particles' keys, float positions (padded to a whole group of four) and candidates.
  std::vector<glm::ivec2> sort_cell_;
  std::vector<std::uint64_t> sort_key_;
  std::vector<std::uint32_t> sort_ids_, sort_scratch_, sort_counts_;
  std::vector<std::uint64_t> sorted_key_;
  std::vector<float> sorted_x_, sorted_y_;
  std::vector<std::array<std::uint32_t, 3>> ranges_;  // row end, below, below end
};

}  // namespace downpour::sim
