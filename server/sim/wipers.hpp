// Wiper kinematics: the blades' angles over time for each wiper mode. A cycle goes from park to
// the full sweep and back with a smooth (cosine) profile, so the blades slow to a stop at both
// ends. Switching a running wiper OFF lets it finish its cycle and park, as a real one does.
#pragma once

#include <array>

#include "server/sim/types.hpp"
#include "server/sim/windshield.hpp"

namespace downpour::sim {

class WiperMotion {
 public:
  explicit WiperMotion(const WiperConfig& config) : config_(config) {}

  void advance(double dt_s, const WiperState& state);

  // Fraction of the sweep, 0 at park and 1 at the far end, per blade.
  double sweep_fraction(int blade) const;
  BladePose pose(int blade) const;
  std::array<BladePose, 2> poses() const { return {pose(0), pose(1)}; }
  bool parked() const;

 private:
  double cycles_per_s(WiperMode mode) const;

  WiperConfig config_;
  double phase_ = 0.0;  // position in the current cycle, [0, 1); 0 = parked
  bool running_ = false;
  double dwell_s_ = 0.0;  // intermittent: time parked since the last cycle ended
  WiperMode last_mode_ = WiperMode::kOff;
  std::array<double, 2> manual_fraction_{0.0, 0.0};  // sweep fractions while in kManual
  bool manual_ = false;
};

}  // namespace downpour::sim
