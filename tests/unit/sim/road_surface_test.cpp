// The road's height field: the track's crowned section, ruts in the wheel paths, seeded bowls clear
// of the crown's top, nothing off the paved width, and the same relief for the same seed wherever
// and whenever it is asked for.
#include "server/sim/road_surface.hpp"

#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

namespace downpour::sim {
namespace {

class RoadSurfaceTest : public ::testing::Test {
 protected:
  Track track = Track::test_track();
  RoadSurface surface{track, 42};
};

TEST_F(RoadSurfaceTest, ReliefIsBelowTheSectionOnThePavedWidthAndNoneOffIt) {
  const double half = track.paved_half_width();
  double deepest = 0.0;
  for (double s = 0.0; s < track.length(); s += 0.7) {
    for (double lateral = -half - 3.0; lateral <= half + 3.0; lateral += 0.13) {
      const double r = surface.relief(s, lateral);
      if (!surface.paved({0, s, lateral})) {
        ASSERT_EQ(r, 0.0) << s << " " << lateral;
        continue;
      }
      ASSERT_LE(r, 0.0);
      deepest = std::min(deepest, r);
      EXPECT_NEAR(surface.height_at(s, lateral), track.surface_height(s, lateral) + r, 1e-12);
    }
  }
  std::printf("deepest relief: %.1f mm\n", -deepest * 1e3);
  EXPECT_LT(deepest, -RoadSurface::kDepressionMinDepthM);
  EXPECT_GT(deepest, -0.06) << "millimetres to a few centimetres, not a pothole";
}

TEST_F(RoadSurfaceTest, WheelPathsAreRuttedAndTheCrownsTopIsNot) {
  for (double s = 0.0; s < track.length(); s += 5.3) {
    for (int lane = 0; lane < track.cross_section().lanes_each_way; ++lane) {
      for (const double side : {-1.0, 1.0}) {
        const double centre = side * track.lane_centre(lane);
        for (const double path :
             {centre - RoadSurface::kWheelPathOffsetM, centre + RoadSurface::kWheelPathOffsetM}) {
          EXPECT_LE(surface.relief(s, path), -RoadSurface::kRutMinDepthM + 1e-12)
              << "s " << s << " wheel path " << path;
        }
      }
    }
    for (double lateral = -RoadSurface::kCrownClearM; lateral <= RoadSurface::kCrownClearM;
         lateral += 0.05)
      EXPECT_EQ(surface.relief(s, lateral), 0.0) << "the crown's top at s " << s;
  }
}

TEST_F(RoadSurfaceTest, BowlsAreSeededAboutOnePerSpacing) {
  // Between the wheel paths of a lane (its centre) only bowls lower the surface.
  int lowered = 0, samples = 0;
  for (double s = 0.0; s < track.length(); s += 0.5) {
    for (int lane = 0; lane < track.cross_section().lanes_each_way; ++lane) {
      ++samples;
      lowered += surface.relief(s, track.lane_centre(lane)) < -0.001;
    }
  }
  std::printf("lane centres lowered by a bowl: %d of %d samples\n", lowered, samples);
  EXPECT_GT(lowered, samples / 100);
  EXPECT_LT(lowered, samples / 3);
}

TEST_F(RoadSurfaceTest, TheSameSeedGivesTheSameReliefAnywhereAndAnotherSeedAnother) {
  const RoadSurface again(track, 42);
  const RoadSurface other(track, 43);
  int differ = 0;
  for (double s = -50.0; s < track.length() + 50.0; s += 1.1) {
    for (double lateral = -8.0; lateral <= 8.0; lateral += 0.37) {
      ASSERT_EQ(surface.relief(s, lateral), again.relief(s, lateral));
      differ += surface.relief(s, lateral) != other.relief(s, lateral);
    }
  }
  EXPECT_GT(differ, 1000);
  // The loop closes: s and s + length are the same place.
  for (double lateral = -8.0; lateral <= 8.0; lateral += 0.37)
    EXPECT_NEAR(surface.relief(3.0, lateral), surface.relief(3.0 + track.length(), lateral), 1e-12);
}

TEST_F(RoadSurfaceTest, WorldPositionsFindTheirPlaceOnTheTrack) {
  for (double s = 10.0; s < track.length(); s += 97.0) {
    const TrackFrame f = track.at(s);
    for (const double lateral : {-7.5, -2.55, -0.95, 0.0, 1.7, 4.45, 8.2}) {
      const glm::dvec2 xy = glm::dvec2(f.position) + f.left * lateral;
      EXPECT_NEAR(surface.height(xy), surface.height_at(s, lateral), 0.002)
          << "s " << s << " lateral " << lateral;
    }
  }
}

}  // namespace
}  // namespace downpour::sim
