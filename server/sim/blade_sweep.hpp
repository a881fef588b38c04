// The wiper blades on the water (seed 000, sections 1.2-1.3): a moving blade pushes the
// particles it reaches ahead of its leading edge, stacked in the order they stood (a strip too deep
// for the particles' region gathered into as many as fit), and turns the mesh drops it touches
// into equal particles. The test is continuous: a point ahead of the blade before the step and
// within reach of it after was swept, however far the blade turned.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "server/sim/mesh_model.hpp"
#include "server/sim/particle_model.hpp"
#include "server/sim/random.hpp"

namespace downpour::sim {

struct WaterInputs;

class BladeSweep {
 public:
  BladeSweep(const WaterConfig& config, std::uint64_t seed);

  void sweep(const WaterInputs& inputs, MeshModel& mesh, ParticleModel& particles);
  // Water each blade has gathered from drops but not yet a whole particle's worth, mg: it rides
  // on the blade's edge (and counts as on the glass).
  double carried() const { return carried_[0] + carried_[1]; }
  // Touched by a blade with the particle budget spent: wiped off at once, mg.
  double wiped_off() const { return wiped_off_; }

 private:
  WaterConfig config_;
  RandomStream random_;
  std::array<double, 2> carried_{};
  struct Swept {         // a particle a blade reached in a step (scratch)
    std::int64_t strip;  // along the blade, a particle wide
    double across;       // across the blade after the step, towards its motion, mm
    double along;        // along the blade after it, mm
    std::uint32_t index;
  };
  std::vector<Swept> swept_;
  std::vector<int> near_;  // the drops in the cells a blade's step reaches (scratch)
  double wiped_off_ = 0.0;
};

}  // namespace downpour::sim
