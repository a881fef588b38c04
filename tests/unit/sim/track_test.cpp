#include "server/sim/track.hpp"

#include <cmath>
#include <numbers>
#include <random>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>

namespace downpour::sim {
namespace {

constexpr double kPi = std::numbers::pi;

// Difference of two angles folded into (-pi, pi].
double angle_diff(double a, double b) { return std::remainder(a - b, 2.0 * kPi); }

// Distance of two arc lengths around a loop of the given length.
double loop_distance(double a, double b, double length) {
  return std::abs(std::remainder(a - b, length));
}

class TrackTest : public ::testing::Test {
 protected:
  const Track track_ = Track::test_track();
};

TEST_F(TrackTest, LengthIsTwoStraightsAndTwoHalfCircles) {
  EXPECT_NEAR(track_.length(), 2.0 * 900.0 + 2.0 * kPi * 250.0, 1e-6);
}

TEST_F(TrackTest, LoopCloses) {
  const TrackFrame start = track_.at(0.0);
  const TrackFrame end = track_.at(track_.length());
  EXPECT_LT(glm::length(start.position - end.position), 1e-3);
  // Approaching the end from below: the heading has turned a full circle.
  const TrackFrame just_before = track_.at(track_.length() - 1e-6);
  EXPECT_LT(glm::length(start.position - just_before.position), 1e-3);
  EXPECT_NEAR(std::abs(angle_diff(start.heading_rad, just_before.heading_rad)), 0.0, 1e-6);
  EXPECT_NEAR(std::abs(just_before.heading_rad - start.heading_rad), 2.0 * kPi, 1e-6);
}

TEST_F(TrackTest, SWrapsAroundTheLoop) {
  for (double s : {0.0, 123.4, 1000.0, 2500.0}) {
    const TrackFrame a = track_.at(s);
    const TrackFrame b = track_.at(s + track_.length());
    const TrackFrame c = track_.at(s - track_.length());
    EXPECT_LT(glm::length(a.position - b.position), 1e-6) << "s=" << s;
    EXPECT_LT(glm::length(a.position - c.position), 1e-6) << "s=" << s;
  }
}

TEST_F(TrackTest, HeadingAndPositionAreContinuous) {
  TrackFrame previous = track_.at(0.0);
  for (double s = 1.0; s <= track_.length() + 0.5; s += 1.0) {
    const TrackFrame f = track_.at(s);
    ASSERT_LT(std::abs(angle_diff(f.heading_rad, previous.heading_rad)), 0.02) << "s=" << s;
    // s is horizontal arc length: samples 1 m apart are at most 1 m apart in plan, not much less.
    const double step = glm::length(glm::dvec2(f.position - previous.position));
    ASSERT_LT(step, 1.0 + 1e-6) << "s=" << s;
    ASSERT_GT(step, 0.99) << "s=" << s;
    previous = f;
  }
}

TEST_F(TrackTest, LeftIsUnitAndPerpendicularToTheHeading) {
  for (double s = 0.0; s < track_.length(); s += 37.0) {
    const TrackFrame f = track_.at(s);
    const glm::dvec2 dir(std::cos(f.heading_rad), std::sin(f.heading_rad));
    EXPECT_NEAR(glm::length(f.left), 1.0, 1e-12);
    EXPECT_NEAR(glm::dot(f.left, dir), 0.0, 1e-12);
    // Left of the direction of travel: the cross product points up.
    EXPECT_GT(dir.x * f.left.y - dir.y * f.left.x, 0.0);
  }
}

TEST_F(TrackTest, ProjectInvertsAt) {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> s_dist(0.0, track_.length());
  std::uniform_real_distribution<double> lateral_dist(-10.0, 10.0);
  for (int i = 0; i < 200; ++i) {
    const double s = s_dist(rng);
    const double lateral = lateral_dist(rng);
    const TrackFrame f = track_.at(s);
    const glm::dvec2 xy = glm::dvec2(f.position) + f.left * lateral;
    const Track::Projection p = track_.project(xy);
    EXPECT_LT(loop_distance(p.s, s, track_.length()), 0.05) << "s=" << s << " lateral=" << lateral;
    EXPECT_NEAR(p.lateral, lateral, 0.05) << "s=" << s << " lateral=" << lateral;
    EXPECT_GE(p.s, 0.0);
    EXPECT_LT(p.s, track_.length());
  }
}

TEST_F(TrackTest, ProjectAcrossTheSeam) {
  for (double s : {0.01, track_.length() - 0.01, 2.0, track_.length() - 2.0}) {
    const TrackFrame f = track_.at(s);
    const Track::Projection p = track_.project(glm::dvec2(f.position) + f.left * 3.0);
    EXPECT_LT(loop_distance(p.s, s, track_.length()), 0.05) << "s=" << s;
    EXPECT_NEAR(p.lateral, 3.0, 0.05) << "s=" << s;
  }
}

TEST_F(TrackTest, SurfaceIsHighestAtTheCentrelineAndFallsWithTheCrown) {
  const double crown = track_.cross_section().crown_slope;
  const double half = track_.paved_half_width();
  EXPECT_NEAR(half, 2 * 3.5 + 1.5, 1e-12);
  for (double s : {10.0, 1000.0, 2135.0, 2300.0}) {
    const double centre = track_.surface_height(s, 0.0);
    EXPECT_NEAR(centre, track_.at(s).position.z, 1e-12) << "s=" << s;
    for (double lateral : {-8.5, -5.25, -1.0, -0.1, 0.1, 1.0, 5.25, 8.5}) {
      const double h = track_.surface_height(s, lateral);
      EXPECT_LT(h, centre) << "s=" << s << " lateral=" << lateral;
      EXPECT_NEAR(centre - h, crown * std::abs(lateral), 1e-12)
          << "s=" << s << " lateral=" << lateral;
    }
    // Symmetric about the centreline.
    EXPECT_DOUBLE_EQ(track_.surface_height(s, 4.0), track_.surface_height(s, -4.0));
  }
}

TEST_F(TrackTest, CrestReachesTenMetresOnTheBackStraight) {
  double highest = -1e9;
  double highest_s = 0.0;
  for (double s = 0.0; s < track_.length(); s += 0.5) {
    const double z = track_.at(s).position.z;
    EXPECT_GE(z, -1e-12) << "s=" << s;
    if (z > highest) {
      highest = z;
      highest_s = s;
    }
  }
  EXPECT_NEAR(highest, 10.0, 1e-3);
  // The back straight runs from 900 + pi * 250 to 1800 + pi * 250.
  EXPECT_GT(highest_s, 900.0 + kPi * 250.0);
  EXPECT_LT(highest_s, 1800.0 + kPi * 250.0);
  // The front straight is level.
  EXPECT_EQ(track_.at(450.0).position.z, 0.0);
}

TEST_F(TrackTest, GradeIsTheDerivativeOfElevation) {
  const double h = 0.01;
  double largest_grade = 0.0;
  for (double s = 0.0; s < track_.length(); s += 2.5) {
    const double dz = (track_.at(s + h).position.z - track_.at(s - h).position.z) / (2.0 * h);
    EXPECT_NEAR(track_.at(s).grade, dz, 1e-5) << "s=" << s;
    largest_grade = std::max(largest_grade, std::abs(track_.at(s).grade));
  }
  // A 10 m raised-cosine crest over 700 m: the steepest grade is 10 * pi / 2 / 350.
  EXPECT_NEAR(largest_grade, 10.0 * kPi / 2.0 / 350.0, 1e-4);
}

TEST_F(TrackTest, LaneCentresAreRightOfTheCentreline) {
  const double w = track_.cross_section().lane_width_m;
  EXPECT_DOUBLE_EQ(track_.lane_centre(0), -0.5 * w);
  EXPECT_DOUBLE_EQ(track_.lane_centre(1), -1.5 * w);
  EXPECT_LT(std::abs(track_.lane_centre(1)), track_.paved_half_width());
}

}  // namespace
}  // namespace downpour::sim
