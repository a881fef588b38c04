#include "server/sim/wipers.hpp"

#include <algorithm>
#include <cmath>

namespace downpour::sim {

double WiperMotion::cycles_per_s(WiperMode mode) const {
  return (mode == WiperMode::kHigh ? config_.high_cycles_per_min : config_.low_cycles_per_min) /
         60.0;
}

void WiperMotion::advance(double dt_s, const WiperState& state) {
  const WiperMode mode = state.mode;
  if (mode == WiperMode::kManual) {
    // The client drives the blades: angles from park, one per blade (one value drives both).
    for (int i = 0; i < 2; ++i) {
      const auto& angles = state.blade_angle_deg;
      const double deg = angles.empty() ? 0.0 : angles[std::min<std::size_t>(i, angles.size() - 1)];
      manual_fraction_[i] = std::clamp(deg / config_.blades[i].sweep_deg, 0.0, 1.0);
    }
    manual_ = true;
    running_ = false;
    phase_ = 0.0;
    last_mode_ = mode;
    return;
  }
  if (manual_) {
    // Leaving manual control: the blades return to park from where they are.
    manual_ = false;
    const double f = std::max(manual_fraction_[0], manual_fraction_[1]);
    if (f > 0.0) {
      phase_ = 1.0 - std::acos(1.0 - 2.0 * f) / (2.0 * M_PI);
      running_ = true;
    }
  }
  const bool switched = mode != last_mode_;
  last_mode_ = mode;
  switch (mode) {
    case WiperMode::kOff:
      break;  // a running cycle finishes and parks
    case WiperMode::kLow:
    case WiperMode::kHigh:
      running_ = true;
      break;
    case WiperMode::kIntermittent:
      if (!running_) {
        dwell_s_ += dt_s;
        if (switched || dwell_s_ >= state.interval_s) running_ = true;
      }
      break;
    case WiperMode::kSingle:
      if (switched) running_ = true;  // one wipe each time SINGLE is chosen
      break;
    case WiperMode::kManual:
      break;
  }
  if (!running_) return;
  phase_ += dt_s * cycles_per_s(mode);
  if (phase_ < 1.0) return;
  if (mode == WiperMode::kLow || mode == WiperMode::kHigh) {
    phase_ -= std::floor(phase_);
  } else {
    phase_ = 0.0;
    running_ = false;
    dwell_s_ = 0.0;
  }
}

double WiperMotion::sweep_fraction(int blade) const {
  if (manual_) return manual_fraction_[blade];
  return 0.5 * (1.0 - std::cos(2.0 * M_PI * phase_));
}

bool WiperMotion::parked() const { return sweep_fraction(0) == 0.0 && sweep_fraction(1) == 0.0; }

BladePose WiperMotion::pose(int blade) const {
  const BladeConfig& b = config_.blades[blade];
  const double deg = b.park_deg + b.turn * b.sweep_deg * sweep_fraction(blade);
  return {glm::vec2(b.pivot_mm), static_cast<float>(deg * M_PI / 180.0),
          static_cast<float>(b.length_mm), static_cast<float>(b.width_mm)};
}

}  // namespace downpour::sim
