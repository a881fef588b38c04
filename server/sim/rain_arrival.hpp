// Rain reaching the windshield, from physics (beyond seed 000): impacts per second = the
// Marshall-Palmer number density of each drop size x its speed through the glass (the air relative
// to the car plus its terminal fall) x the glass's area. Driving faster collects more water.
#pragma once

#include <cstdint>
#include <functional>

#include <glm/vec2.hpp>

#include "server/sim/random.hpp"
#include "server/sim/windshield.hpp"

namespace downpour::sim {

struct WaterInputs;

class RainArrival {
 public:
  RainArrival(const WindshieldConfig& config, std::uint64_t seed);

  // The raindrops that hit the glass during dt, each handed to land(pos_mm, mass_mg) in turn.
  void step(double dt, const WaterInputs& inputs,
            const std::function<void(glm::dvec2, double)>& land);
  // The stream the impacts are drawn from, which also shapes their sub-metaballs.
  RandomStream& random() { return random_; }

 private:
  WindshieldConfig config_;
  RandomStream random_;
};

}  // namespace downpour::sim
