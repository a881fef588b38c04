#include "server/sim/pose.hpp"

#include <random>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>
#include <glm/matrix.hpp>
#include <glm/trigonometric.hpp>

namespace downpour::sim {
namespace {

void expect_near(const glm::dvec3& a, const glm::dvec3& b, double tolerance) {
  EXPECT_NEAR(a.x, b.x, tolerance);
  EXPECT_NEAR(a.y, b.y, tolerance);
  EXPECT_NEAR(a.z, b.z, tolerance);
}

TEST(PoseTest, IdentityForZeroAngles) {
  const glm::dmat3 r = rotation_matrix({0.0, 0.0, 0.0});
  for (int c = 0; c < 3; ++c) {
    for (int row = 0; row < 3; ++row) EXPECT_EQ(r[c][row], c == row ? 1.0 : 0.0);
  }
}

TEST(PoseTest, YawNinetyMapsForwardToLeft) {
  const glm::dmat3 r = rotation_matrix({90.0, 0.0, 0.0});
  expect_near(r * glm::dvec3(1, 0, 0), glm::dvec3(0, 1, 0), 1e-12);
  expect_near(r * glm::dvec3(0, 1, 0), glm::dvec3(-1, 0, 0), 1e-12);
  expect_near(r * glm::dvec3(0, 0, 1), glm::dvec3(0, 0, 1), 1e-12);
}

TEST(PoseTest, PositivePitchPutsTheNoseDown) {
  const glm::dvec3 nose = rotation_matrix({0.0, 10.0, 0.0}) * glm::dvec3(1, 0, 0);
  EXPECT_LT(nose.z, 0.0);
  EXPECT_GT(nose.x, 0.0);
  EXPECT_NEAR(nose.y, 0.0, 1e-12);
  // The nose stays down whatever the heading.
  EXPECT_LT((rotation_matrix({135.0, 10.0, 0.0}) * glm::dvec3(1, 0, 0)).z, 0.0);
}

TEST(PoseTest, PositiveRollLowersTheRightSide) {
  // Roll about +x (right-handed): the left side (+y) goes up, the right side down.
  const glm::dvec3 left = rotation_matrix({0.0, 0.0, 10.0}) * glm::dvec3(0, 1, 0);
  EXPECT_GT(left.z, 0.0);
}

TEST(PoseTest, OrderIsYawThenPitchThenRoll) {
  // Pitching the vehicle after a 90 degree yaw still tilts its own nose, which now points along +y.
  const glm::dvec3 nose = rotation_matrix({90.0, 30.0, 0.0}) * glm::dvec3(1, 0, 0);
  expect_near(nose, glm::dvec3(0.0, std::cos(glm::radians(30.0)), -std::sin(glm::radians(30.0))),
              1e-12);
}

TEST(PoseTest, MatrixIsOrthonormalForArbitraryAngles) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> angle(-720.0, 720.0);
  for (int i = 0; i < 100; ++i) {
    const Rotation rot{angle(rng), angle(rng), angle(rng)};
    const glm::dmat3 r = rotation_matrix(rot);
    const glm::dmat3 should_be_identity = glm::transpose(r) * r;
    for (int c = 0; c < 3; ++c) {
      for (int row = 0; row < 3; ++row) {
        EXPECT_NEAR(should_be_identity[c][row], c == row ? 1.0 : 0.0, 1e-12);
      }
    }
    // A rotation, not a reflection.
    EXPECT_NEAR(glm::determinant(r), 1.0, 1e-12);
  }
}

TEST(PoseTest, VehicleToWorldRotatesThenTranslates) {
  VehicleState v;
  v.position_m = {10.0, 20.0, 3.0};
  v.rotation = {90.0, 0.0, 0.0};
  const glm::dmat4 m = vehicle_to_world(v);
  // A point 2 m ahead of the vehicle lies 2 m along world +y from it.
  const glm::dvec4 ahead = m * glm::dvec4(2.0, 0.0, 0.0, 1.0);
  expect_near(glm::dvec3(ahead), glm::dvec3(10.0, 22.0, 3.0), 1e-12);
  EXPECT_EQ(ahead.w, 1.0);
  // Directions (w = 0) are not translated.
  const glm::dvec4 dir = m * glm::dvec4(1.0, 0.0, 0.0, 0.0);
  expect_near(glm::dvec3(dir), glm::dvec3(0.0, 1.0, 0.0), 1e-12);
}

}  // namespace
}  // namespace downpour::sim
