// Wiper kinematics per mode.
#include "server/sim/wipers.hpp"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

namespace downpour::sim {
namespace {

constexpr double kDt = 1.0 / 240.0;

// Seconds from the first motion to the return to park, under a fixed state.
double cycle_seconds(WiperMotion& w, const WiperState& state) {
  double t = 0.0;
  bool moved = false;
  for (int i = 0; i < 240 * 10; ++i) {
    w.advance(kDt, state);
    t += kDt;
    if (!w.parked()) moved = true;
    if (moved && w.parked()) return t;
  }
  return -1.0;
}

// Seconds between the returns to park of a continuously running wiper.
double period_seconds(WiperMode mode) {
  WiperMotion w({});
  std::vector<double> returns;
  double before = 0.0, previous = 0.0;
  for (int i = 0; i < 240 * 6; ++i) {
    w.advance(kDt, {mode, 4.0, {}});
    const double f = w.sweep_fraction(0);
    if (i > 1 && previous < before && previous <= f) returns.push_back(i * kDt);  // a minimum
    before = previous;
    previous = f;
  }
  return returns.size() >= 2 ? returns[1] - returns[0] : -1.0;
}

TEST(WipersTest, LowAndHighRunAtTheirCycleRates) {
  EXPECT_NEAR(period_seconds(WiperMode::kLow), 60.0 / 45.0, 2 * kDt);
  EXPECT_NEAR(period_seconds(WiperMode::kHigh), 60.0 / 65.0, 2 * kDt);
}

TEST(WipersTest, TheSweepIsSmoothAndReachesTheFullAngle) {
  WiperMotion w({});
  const WiperConfig config;
  double widest = 0.0, largest_step = 0.0, previous = 0.0;
  for (int i = 0; i < 240; ++i) {
    w.advance(kDt, {WiperMode::kHigh, 4.0, {}});
    const double f = w.sweep_fraction(0);
    widest = std::max(widest, f);
    largest_step = std::max(largest_step, std::abs(f - previous));
    previous = f;
  }
  EXPECT_NEAR(widest, 1.0, 1e-3);
  // Peak speed of a cosine profile: pi * cycles per second * dt of the sweep per step.
  EXPECT_LT(largest_step, M_PI * 65.0 / 60.0 * kDt * 1.01);
  const BladePose up = w.pose(0);
  EXPECT_NEAR(up.length_mm, config.blades[0].length_mm, 1e-3);
}

TEST(WipersTest, SingleWipesOnceThenParks) {
  WiperMotion w({});
  const double t = cycle_seconds(w, {WiperMode::kSingle, 4.0, {}});
  EXPECT_NEAR(t, 60.0 / 45.0, 2 * kDt);
  for (int i = 0; i < 240 * 3; ++i) {
    w.advance(kDt, {WiperMode::kSingle, 4.0, {}});
    ASSERT_TRUE(w.parked()) << "a second wipe without a new request";
  }
}

TEST(WipersTest, IntermittentWaitsItsIntervalBetweenWipes) {
  WiperMotion w({});
  const WiperState state{WiperMode::kIntermittent, 2.0, {}};
  std::vector<double> starts;
  bool was_parked = true;
  for (int i = 0; i < 240 * 10; ++i) {
    w.advance(kDt, state);
    if (was_parked && !w.parked()) starts.push_back(i * kDt);
    was_parked = w.parked();
  }
  ASSERT_GE(starts.size(), 3u);
  EXPECT_NEAR(starts[1] - starts[0], 60.0 / 45.0 + 2.0, 3 * kDt);
}

TEST(WipersTest, OffFinishesTheCycleAndParks) {
  WiperMotion w({});
  for (int i = 0; i < 60; ++i) w.advance(kDt, {WiperMode::kHigh, 4.0, {}});
  ASSERT_FALSE(w.parked());
  int steps = 0;
  while (!w.parked() && steps < 240 * 3) {
    w.advance(kDt, {WiperMode::kOff, 4.0, {}});
    ++steps;
  }
  EXPECT_TRUE(w.parked());
  for (int i = 0; i < 240; ++i) {
    w.advance(kDt, {WiperMode::kOff, 4.0, {}});
    EXPECT_TRUE(w.parked());
  }
}

TEST(WipersTest, ManualFollowsTheClientsAnglesClampedToTheSweep) {
  WiperMotion w({});
  const WiperConfig config;
  w.advance(kDt, {WiperMode::kManual, 4.0, {30.0, 200.0}});
  EXPECT_NEAR(w.sweep_fraction(0), 30.0 / config.blades[0].sweep_deg, 1e-12);
  EXPECT_NEAR(w.sweep_fraction(1), 1.0, 1e-12);
  EXPECT_NEAR(w.pose(0).angle_rad, (config.blades[0].park_deg + 30.0) * M_PI / 180.0, 1e-6);
  // Back to OFF: the blades return to park.
  int steps = 0;
  while (!w.parked() && steps < 240 * 3) {
    w.advance(kDt, {WiperMode::kOff, 4.0, {}});
    ++steps;
  }
  EXPECT_TRUE(w.parked());
}

}  // namespace
}  // namespace downpour::sim
