// The water on the road: every cubic metre accounted for over ten minutes of heavy rain on the
// move; puddles in ruts, bowls and at the edge, never on the crown's top; a cell walks Dry, Wet,
// Drench, Puddle as water rises; puddles shrink once the rain stops; water stays where it fell
// when the car drives away and back; the same inputs give the same water; the renderer's image of
// the window.
#include "server/sim/road_water.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <set>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

namespace downpour::sim {
namespace {

class RoadWaterTest : public ::testing::Test {
 protected:
  glm::dvec2 at(double s, double lateral) const {
    const TrackFrame f = track.at(s);
    return glm::dvec2(f.position) + f.left * lateral;
  }
  // The window's puddle cells, in world cells.
  std::set<std::pair<int, int>> puddles(const RoadWater& water) const {
    std::set<std::pair<int, int>> out;
    const int n = water.cells();
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        if (water.state_of(water.water()[j * n + i]) == RoadState::kPuddle)
          out.emplace(water.origin().x + i, water.origin().y + j);
      }
    }
    return out;
  }
  Track::Projection place(const RoadWater& water, std::pair<int, int> cell) const {
    const glm::dvec2 xy = (glm::dvec2(cell.first, cell.second) + 0.5) * water.config().cell_m;
    return track.project(xy, 40.0);
  }

  Track track = Track::test_track();
  RoadSurface surface{track, 7};
};

TEST_F(RoadWaterTest, TheLedgerClosesOverTenMinutesOfHeavyRainOnTheMove) {
  RoadWaterConfig config;
  config.cells = 64;  // 16 m: the test's speed
  RoadWater water(surface, config);
  const double dt = 0.2;
  double s = 0.0;
  for (int k = 0; k < 3000; ++k) {  // 10 minutes: 4 standing, 2 at 25 m/s, 4 standing
    if (k >= 1200 && k < 1800) s += 25.0 * dt;
    const double rain = k < 2700 ? 30.0 : 0.0;  // the last minute dry: evaporation too
    water.step(at(s, track.lane_centre(0)), rain, dt);
    if (k % 5 == 0) water.take(at(s, track.lane_centre(0) + 0.8), 1e-5);  // spray
  }
  const RoadWater::Ledger& l = water.ledger();
  const double out = water.stored_m3() + l.drained_m3 + l.evaporated_m3 + l.thrown_m3;
  std::printf("in %.6f m^3: stored %.6f, drained %.6f, evaporated %.9f, thrown %.6f\n",
              l.rain_in_m3, water.stored_m3(), l.drained_m3, l.evaporated_m3, l.thrown_m3);
  EXPECT_GT(l.rain_in_m3, 1.0);
  EXPECT_GT(l.drained_m3, 0.0);
  EXPECT_GT(l.evaporated_m3, 0.0);
  EXPECT_GT(l.thrown_m3, 0.0);
  EXPECT_NEAR(out, l.rain_in_m3, 1e-9 * l.rain_in_m3);
}

TEST_F(RoadWaterTest, PuddlesFormInRutsBowlsAndAtTheEdgeNeverOnTheCrown) {
  RoadWater water(surface);
  const glm::dvec2 centre = at(150.0, 0.0);  // on the first straight
  std::set<std::pair<int, int>> first;
  double first_time = -1.0;
  const double dt = 0.1;
  for (int k = 1; k <= 3000; ++k) {  // 5 minutes of 30 mm/h
    water.step(centre, 30.0, dt);
    if (first.empty()) {
      first = puddles(water);
      if (!first.empty()) first_time = k * dt;
    }
  }
  const std::set<std::pair<int, int>> later = puddles(water);
  std::printf("first puddles after %.1f s: %zu cells; after 5 min: %zu\n", first_time, first.size(),
              later.size());
  ASSERT_FALSE(first.empty());
  const double edge = track.paved_half_width();
  auto low_or_edge = [&](std::pair<int, int> cell) {
    const Track::Projection p = place(water, cell);
    return surface.relief(p.s, p.lateral) < -0.001 || std::abs(p.lateral) > edge - 1.0;
  };
  for (const auto& cell : first) EXPECT_TRUE(low_or_edge(cell)) << "a first puddle on high ground";
  int on_low = 0;
  for (const auto& cell : later) {
    const Track::Projection p = place(water, cell);
    EXPECT_GT(std::abs(p.lateral), RoadSurface::kCrownClearM) << "a puddle on the crown's top";
    on_low += low_or_edge(cell);
  }
  EXPECT_GT(on_low, static_cast<int>(later.size()) * 9 / 10);
}

TEST_F(RoadWaterTest, ACellWalksDryWetDrenchPuddleAndPuddlesShrinkWhenTheRainStops) {
  RoadWater water(surface);
  const glm::dvec2 centre = at(150.0, 0.0);
  // Every cell's first time in each state, and whether its state ever fell while it rained.
  const int n = water.cells();
  std::vector<std::array<double, 4>> reached(n * n, {0.0, -1.0, -1.0, -1.0});
  std::vector<RoadState> last(n * n, RoadState::kDry);
  int fell = 0;
  const double dt = 0.1;
  for (int k = 1; k <= 3000; ++k) {
    water.step(centre, 30.0, dt);
    for (int c = 0; c < n * n; ++c) {
      const RoadState now = water.state_of(water.water()[c]);
      fell += now < last[c];
      if (reached[c][static_cast<int>(now)] < 0.0) reached[c][static_cast<int>(now)] = k * dt;
      last[c] = now;
    }
  }
  // Water running over a cell can leave it lower for a while (a puddle's rim between inflows), but
  // the model does not ring: few cells' states fall at all.
  std::printf("states fell %d times over %d cells in 5 minutes\n", fell, n * n);
  EXPECT_LT(fell, n * n / 4);
  int walked = 0;
  for (int c = 0; c < n * n; ++c) {
    if (reached[c][3] < 0.0) continue;
    ++walked;
    EXPECT_GT(reached[c][1], 0.0);
    EXPECT_GT(reached[c][2], reached[c][1]);
    EXPECT_GT(reached[c][3], reached[c][2]);
    if (walked == 1) {
      std::printf("a puddle cell: wet at %.1f s, drench %.1f s, puddle %.1f s\n", reached[c][1],
                  reached[c][2], reached[c][3]);
    }
  }
  EXPECT_GT(walked, 0);

  // The rain stops: the film runs off, then evaporation takes the puddles' shallow edges.
  const std::size_t wet_puddles = puddles(water).size();
  double standing_before = 0.0;
  for (const double w : water.water()) standing_before += w;
  for (int k = 0; k < 1800; ++k) water.step(centre, 0.0, 1.0);  // 30 minutes
  const std::size_t dry_puddles = puddles(water).size();
  double standing_after = 0.0;
  for (const double w : water.water()) standing_after += w;
  std::printf("puddle cells: %zu when the rain stopped, %zu 30 min later\n", wet_puddles,
              dry_puddles);
  EXPECT_LT(dry_puddles, wet_puddles);
  EXPECT_LT(standing_after, 0.8 * standing_before);
}

TEST_F(RoadWaterTest, WaterStaysWhereItFellWhenTheCarDrivesAwayAndBack) {
  // Two cars in the same rain: one drives 200 m away and back while the other waits.
  RoadWater trip(surface), wait(surface);
  const double s0 = 150.0;
  for (RoadWater* water : {&trip, &wait}) {
    for (int k = 0; k < 1800; ++k) water->step(at(s0, 0.0), 30.0, 0.1);  // 3 minutes
  }
  const std::set<std::pair<int, int>> when_left = puddles(trip);
  for (int k = 1; k <= 20; ++k) trip.step(at(s0 + 10.0 * k, 0.0), 0.0, 0.5);
  for (int k = 19; k >= 0; --k) trip.step(at(s0 + 10.0 * k, 0.0), 0.0, 0.5);
  for (int k = 0; k < 40; ++k) wait.step(at(s0, 0.0), 0.0, 0.5);
  // Then both settle for a minute.
  for (RoadWater* water : {&trip, &wait}) {
    for (int k = 0; k < 600; ++k) water->step(at(s0, 0.0), 0.0, 0.1);
  }
  const std::set<std::pair<int, int>> after_trip = puddles(trip), after_wait = puddles(wait);
  int both = 0;
  for (const auto& cell : after_trip) both += after_wait.count(cell);
  auto in_window = [&](const RoadWater& water) {
    double sum = 0.0;
    for (const double w : water.water()) sum += w * 0.25 * 0.25;
    return sum;
  };
  std::printf(
      "puddle cells: %zu when the car left; a minute after it came back %zu, %zu for the car that "
      "waited, %d in both; water in the window %.4f against %.4f m^3\n",
      when_left.size(), after_trip.size(), after_wait.size(), both, in_window(trip),
      in_window(wait));
  ASSERT_FALSE(after_wait.empty());
  EXPECT_GT(both, static_cast<int>(after_wait.size()) * 8 / 10);
  EXPECT_LT(after_trip.size(), after_wait.size() * 5 / 4);
  // The film that ran off while the car was away is counted as drained as it left: the window
  // holds as much as the waiting car's but for that.
  EXPECT_GT(in_window(trip), 0.7 * in_window(wait));
}

TEST_F(RoadWaterTest, TheSameInputsGiveTheSameWater) {
  RoadWater a(surface), b(surface);
  const RoadSurface other_surface(track, 8);
  RoadWater c(other_surface);
  for (int k = 0; k < 900; ++k) {  // 90 s of 40 mm/h, the car creeping on at 0.5 m/s
    const glm::dvec2 centre = at(100.0 + 0.05 * k, -1.75);
    a.step(centre, 40.0, 0.1);
    b.step(centre, 40.0, 0.1);
    c.step(centre, 40.0, 0.1);
  }
  EXPECT_EQ(a.water(), b.water());
  EXPECT_NE(a.water(), c.water());
}

TEST_F(RoadWaterTest, TheImageForTheRendererIsTheWindowInMillimetres) {
  RoadWaterConfig config;
  config.cells = 96;  // 24 m: past the right edge of the road
  RoadWater water(surface, config);
  for (int k = 0; k < 600; ++k) water.step(at(250.0, -1.75), 30.0, 0.1);  // a minute of 30 mm/h
  RoadWaterImage image;
  water.image(image);
  const int n = water.cells();
  ASSERT_EQ(image.cells, n);
  EXPECT_EQ(image.origin, water.origin());
  ASSERT_EQ(image.water_standing_mm.size(), static_cast<std::size_t>(n) * n * 2);
  double sum = 0.0, max_standing = 0.0;
  int paved = 0, edge = 0;
  for (int c = 0; c < n * n; ++c) {
    const double w = water.water()[c] * 1e3;
    const double standing = std::max(w - config.capacity_m * 1e3, 0.0);
    if (water.paved()[c]) {
      EXPECT_NEAR(image.water_standing_mm[2 * c], w, 1e-4 * (1.0 + w));
      EXPECT_NEAR(image.water_standing_mm[2 * c + 1], standing, 1e-4 * (1.0 + standing));
      sum += w;
      max_standing = std::max(max_standing, standing);
      ++paved;
    } else if (image.water_standing_mm[2 * c] > 0.0f) {
      ++edge;  // beside the road: its neighbours' water, so that the road's edge draws smooth
      EXPECT_EQ(water.water()[c], 0.0);
    }
  }
  ASSERT_GT(paved, 0);
  EXPECT_GT(edge, 0);
  EXPECT_NEAR(image.mean_water_mm, sum / paved, 1e-4 * sum / paved);
  EXPECT_NEAR(image.max_standing_mm, max_standing, 1e-4 * (1.0 + max_standing));
  EXPECT_GT(image.mean_water_mm, 0.25);  // a minute of 30 mm/h is 0.5 mm
}

}  // namespace
}  // namespace downpour::sim
