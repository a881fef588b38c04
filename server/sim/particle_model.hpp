// The particle model of seed 000 (section 1.2): the water near the wipers as equal
// particles that never fuse; where two overlap both move apart along the line of their centres by
// half the overlap, and further by the overlap times a penalty. Glass space, millimetres.
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
  // Within a blade's region: a rectangle as long as the blade and as wide as the blade plus
  // region_particle_diameters on each side. A blade of negative length has no region.
  bool in_region(glm::dvec2 pos, const std::array<BladePose, 2>& blades) const;

  std::vector<Particle>& particles() { return particles_; }
  const std::vector<Particle>& particles() const { return particles_; }
  double particle_mass() const { return particle_mass_; }  // of one particle, mg
  double mass() const;

 private:
  WaterConfig config_;
  std::vector<Particle> particles_;
  double particle_mass_ = 0.0;
  // Neighbour hash: bucket start offsets and the ids sorted by bucket.
  std::vector<std::uint32_t> hash_start_, hash_fill_;
  std::vector<std::uint32_t> hash_ids_;             // particle index, in bucket order
  std::vector<glm::vec2> hash_pos_;                 // its position, in bucket order
  std::vector<glm::ivec2> hash_cell_;               // grid cell, in particle order
  std::vector<std::uint32_t> hash_neighbours_;      // 9 buckets a particle, in bucket order
  std::vector<std::uint8_t> hash_neighbour_count_;  // how many of them are distinct
};

}  // namespace downpour::sim
