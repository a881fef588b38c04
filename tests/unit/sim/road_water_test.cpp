// The water on the road: every cubic metre accounted for over ten minutes of heavy rain on the
// move across the rings, and with the records trimmed; puddles in ruts, bowls and at the edge,
// never on the crown's top; a cell walks Dry, Wet, Drench, Puddle as water rises; puddles shrink
// once the rain stops; water stays where it fell when the car drives away and back; puddles ahead
// of a fast car; no seam where the rings meet; the same inputs give the same water; the renderer's
// image of the rings.
#include "server/sim/road_water.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <initializer_list>
#include <set>
#include <tuple>
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
  // A cell of the rings: its level and its place in that level's grid.
  using Cell = std::tuple<int, int, int>;
  // The cells that hold their place's water in a puddle.
  std::set<Cell> puddles(const RoadWater& water, int finest_levels = kRoadWaterMaxLevels) const {
    std::set<Cell> out;
    const int n = water.cells();
    for (int l = 0; l < std::min(water.levels(), finest_levels); ++l) {
      for (int j = 0; j < n; ++j) {
        for (int i = 0; i < n; ++i) {
          const std::size_t c = (static_cast<std::size_t>(l) * n + j) * n + i;
          if (water.owned()[c] && water.cell_state(c) == RoadState::kPuddle)
            out.emplace(l, water.origin(l).x + i, water.origin(l).y + j);
        }
      }
    }
    return out;
  }
  glm::dvec2 centre(const RoadWater& water, const Cell& cell) const {
    const auto [l, x, y] = cell;
    return (glm::dvec2(x, y) + 0.5) * water.cell_m(l);
  }
  Track::Projection place(const RoadWater& water, const Cell& cell) const {
    return track.project(centre(water, cell), 40.0);
  }
  // Whether a cell lies on a rut or a bowl (the relief 1 mm deep or more at its centre or near a
  // corner), or within a metre of the paved edge.
  bool in_hollow_or_at_edge(const RoadWater& water, const Cell& cell) const {
    const Track::Projection p = place(water, cell);
    const double half = 0.5 * water.cell_m(std::get<0>(cell));
    double lowest = 0.0;
    for (const glm::dvec2 d :
         {glm::dvec2(0.0), {-half, -half}, {half, -half}, {-half, half}, {half, half}}) {
      const Track::Projection q = track.project_near(centre(water, cell) + d * 0.9, p.s);
      lowest = std::min(lowest, surface.relief(q.s, q.lateral));
    }
    return lowest < -0.001 || std::abs(p.lateral) > track.paved_half_width() - 1.0;
  }
  // Steps each of the models standing at xy.
  static void stand(std::initializer_list<RoadWater*> waters, glm::dvec2 xy, double rain_mm_h,
                    int steps, double dt_s) {
    for (RoadWater* water : waters)
      for (int k = 0; k < steps; ++k) water->step(xy, rain_mm_h, dt_s);
  }
  // How many cells two sets share.
  static int common(const std::set<Cell>& a, const std::set<Cell>& b) {
    int n = 0;
    for (const Cell& cell : a) n += static_cast<int>(b.count(cell));
    return n;
  }
  // The water the rings hold (m^3).
  static double in_rings(const RoadWater& water) {
    const std::size_t per_level = static_cast<std::size_t>(water.cells()) * water.cells();
    double sum = 0.0;
    for (std::size_t c = 0; c < water.water().size(); ++c) {
      const double size = water.cell_m(static_cast<int>(c / per_level));
      sum += water.water()[c] * size * size;
    }
    return sum;
  }

  Track track = Track::test_track();
  RoadSurface surface{track, 7};
};

TEST_F(RoadWaterTest, TheLedgerClosesOverTenMinutesOfHeavyRainOnTheMove) {
  // 10 minutes: 4 standing, 2 at 30 m/s (3.6 km: every ring's border crossed, records left), 4
  // standing; the last minute dry: evaporation too.
  RoadWater water(surface);
  const double dt = 0.2;
  double s = 0.0;
  std::size_t most_records = 0;
  for (int k = 0; k < 3000; ++k) {
    if (k >= 1200 && k < 1800) s += 30.0 * dt;
    const double rain = k < 2700 ? 30.0 : 0.0;
    water.step(at(s, track.lane_centre(0)), rain, dt);
    if (k % 5 == 0) water.take(at(s, track.lane_centre(0) + 0.8), 1e-5);  // spray
    most_records = std::max(most_records, water.records());
  }
  const RoadWater::Ledger& l = water.ledger();
  const double out =
      water.stored_m3() + l.drained_m3 + l.evaporated_m3 + l.thrown_m3 - l.returned_m3;
  std::printf(
      "in %.6f m^3: stored %.6f, drained %.6f, evaporated %.9f, thrown %.6f; %zu records at most\n",
      l.rain_in_m3, water.stored_m3(), l.drained_m3, l.evaporated_m3, l.thrown_m3, most_records);
  EXPECT_GT(l.rain_in_m3, 1.0);
  EXPECT_GT(l.drained_m3, 0.0);
  EXPECT_GT(l.evaporated_m3, 0.0);
  EXPECT_GT(l.thrown_m3, 0.0);
  EXPECT_GT(most_records, 0u);
  EXPECT_NEAR(out, l.rain_in_m3, 1e-9 * l.rain_in_m3);
}

TEST_F(RoadWaterTest, TheRecordsStayBoundedAndTheLedgerStillCloses) {
  RoadWaterConfig config;
  config.max_records = 300;
  RoadWater water(surface, config);
  double s = 0.0;
  std::size_t most = 0;
  for (int k = 0; k < 1500; ++k) {  // 5 minutes at 20 m/s in the rain: 6 km, past the loop
    s += 20.0 * 0.2;
    water.step(at(s, track.lane_centre(0)), 30.0, 0.2);
    most = std::max(most, water.records());
  }
  const RoadWater::Ledger& l = water.ledger();
  const double out =
      water.stored_m3() + l.drained_m3 + l.evaporated_m3 + l.thrown_m3 - l.returned_m3;
  std::printf("%zu records at most (of %zu allowed)\n", most, config.max_records);
  EXPECT_LE(most, config.max_records);
  EXPECT_GT(most, config.max_records / 2);
  EXPECT_NEAR(out, l.rain_in_m3, 1e-9 * l.rain_in_m3);
}

TEST_F(RoadWaterTest, JumpsAnywhereKeepEveryCubicMetre) {
  // A simulator may place the car anywhere at any step: jumps of up to a kilometre, off the road
  // too, back and forth, in rain and dry spells.
  RoadWater water(surface);
  std::uint64_t state = 12345;
  auto next = [&]() {  // a small deterministic stream
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(state >> 11) / static_cast<double>(1ULL << 53);
  };
  double s = 0.0;
  for (int k = 0; k < 400; ++k) {
    s += (next() - 0.3) * (k % 7 == 0 ? 2000.0 : 8.0);
    const double lateral = (next() - 0.5) * (k % 11 == 0 ? 80.0 : 10.0);
    water.step(at(s, lateral), k % 50 < 35 ? 40.0 : 0.0, 0.5);
  }
  const RoadWater::Ledger& l = water.ledger();
  const double out =
      water.stored_m3() + l.drained_m3 + l.evaporated_m3 + l.thrown_m3 - l.returned_m3;
  std::printf("in %.4f m^3, %zu records\n", l.rain_in_m3, water.records());
  EXPECT_GT(l.rain_in_m3, 0.0);
  EXPECT_NEAR(out, l.rain_in_m3, 1e-9 * l.rain_in_m3);
  for (const double w : water.water()) EXPECT_GE(w, 0.0);
}

TEST_F(RoadWaterTest, PuddlesFormInRutsBowlsAndAtTheEdgeNeverOnTheCrown) {
  RoadWater water(surface);
  const glm::dvec2 car = at(150.0, 0.0);  // on the first straight
  std::set<Cell> first;
  double first_time = -1.0;
  const double dt = 0.1;
  for (int k = 1; k <= 3000; ++k) {  // 5 minutes of 30 mm/h
    water.step(car, 30.0, dt);
    if (first.empty()) {
      first = puddles(water);
      if (!first.empty()) first_time = k * dt;
    }
  }
  // The finest two rings: the coarser cells hold the ruts' and bowls' water as a mean.
  const std::set<Cell> later = puddles(water, 2);
  std::printf("first puddles after %.1f s: %zu cells; after 5 min: %zu in the finest two rings\n",
              first_time, first.size(), later.size());
  ASSERT_FALSE(first.empty());
  auto low_or_edge = [&](const Cell& cell) { return in_hollow_or_at_edge(water, cell); };
  for (const auto& cell : first) EXPECT_TRUE(low_or_edge(cell)) << "a first puddle on high ground";
  ASSERT_FALSE(later.empty());
  int on_low = 0;
  for (const auto& cell : later) {
    const Track::Projection p = place(water, cell);
    EXPECT_GT(std::abs(p.lateral), RoadSurface::kCrownClearM) << "a puddle on the crown's top";
    on_low += low_or_edge(cell);
  }
  EXPECT_GT(on_low, static_cast<int>(later.size()) * 9 / 10);
}

TEST_F(RoadWaterTest, NoPuddleOnTheCrestsTopButInItsRutsAndBowls) {
  // The crest's top (10 m high over 700 m of the back straight) sheds water both ways along the
  // road and across it: after 5 minutes of 30 mm/h, what stands there stands in the relief.
  double top = 0.0;
  for (double s = 0.0; s < track.length(); s += 1.0)
    if (track.at(s).position.z > track.at(top).position.z) top = s;
  RoadWater water(surface);
  for (int k = 0; k < 1500; ++k) water.step(at(top, 0.0), 30.0, 0.2);
  const std::set<Cell> found = puddles(water, 2);
  int in_relief = 0;
  for (const Cell& cell : found) in_relief += in_hollow_or_at_edge(water, cell);
  std::printf(
      "crest's top at s = %.0f m: %zu puddle cells in the finest two rings, %d in the relief "
      "or at the edge\n",
      top, found.size(), in_relief);
  EXPECT_FALSE(found.empty());  // (it rains there as elsewhere: the ruts fill)
  EXPECT_EQ(in_relief, static_cast<int>(found.size()));
}

TEST_F(RoadWaterTest, ACellWalksDryWetDrenchPuddleAndPuddlesShrinkWhenTheRainStops) {
  RoadWater water(surface);
  const glm::dvec2 car = at(150.0, 0.0);
  // Every cell's first time in each state, and whether its state ever fell while it rained.
  const std::size_t count = water.water().size();
  std::vector<std::array<double, 4>> reached(count, {0.0, -1.0, -1.0, -1.0});
  std::vector<RoadState> last(count, RoadState::kDry);
  int fell = 0, cells = 0;
  const double dt = 0.1;
  for (int k = 1; k <= 3000; ++k) {
    water.step(car, 30.0, dt);
    for (std::size_t c = 0; c < count; ++c) {
      if (!water.owned()[c]) continue;
      const RoadState now = water.cell_state(c);
      fell += now < last[c];
      if (reached[c][static_cast<int>(now)] < 0.0) reached[c][static_cast<int>(now)] = k * dt;
      last[c] = now;
    }
  }
  for (std::size_t c = 0; c < count; ++c) cells += water.owned()[c];
  // Water running over a cell can leave it lower for a while (a puddle's rim between inflows), but
  // the model does not ring: few cells' states fall at all.
  std::printf("states fell %d times over %d cells in 5 minutes\n", fell, cells);
  EXPECT_LT(fell, cells / 4);
  int walked = 0;
  for (std::size_t c = 0; c < count; ++c) {
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
  const double before = in_rings(water);
  for (int k = 0; k < 1800; ++k) water.step(car, 0.0, 1.0);  // 30 minutes
  const std::size_t dry_puddles = puddles(water).size();
  std::printf("puddle cells: %zu when the rain stopped, %zu 30 min later\n", wet_puddles,
              dry_puddles);
  EXPECT_LT(dry_puddles, wet_puddles);
  EXPECT_LT(in_rings(water), 0.8 * before);
}

TEST_F(RoadWaterTest, WaterStaysWhereItFellWhenTheCarDrivesAwayAndBack) {
  // Two cars in the same rain: one drives 400 m away (out of every ring) and back while the other
  // waits.
  RoadWater trip(surface), wait(surface);
  const double s0 = 150.0;
  stand({&trip, &wait}, at(s0, 0.0), 30.0, 1800, 0.1);  // 3 minutes
  const std::set<Cell> when_left = puddles(trip, 1);
  for (int k = 1; k <= 40; ++k) trip.step(at(s0 + 10.0 * k, 0.0), 0.0, 0.25);
  for (int k = 39; k >= 0; --k) trip.step(at(s0 + 10.0 * k, 0.0), 0.0, 0.25);
  for (int k = 0; k < 40; ++k) wait.step(at(s0, 0.0), 0.0, 0.5);
  stand({&trip, &wait}, at(s0, 0.0), 0.0, 600, 0.1);  // then both settle for a minute
  const std::set<Cell> after_trip = puddles(trip, 1), after_wait = puddles(wait, 1);
  const int both = common(after_trip, after_wait);
  std::printf(
      "puddle cells of the finest ring: %zu when the car left; a minute after it came back %zu, "
      "%zu for the car that waited, %d in both; water in the rings %.4f against %.4f m^3\n",
      when_left.size(), after_trip.size(), after_wait.size(), both, in_rings(trip), in_rings(wait));
  ASSERT_FALSE(after_wait.empty());
  EXPECT_GT(both, static_cast<int>(after_wait.size()) * 7 / 10);
  EXPECT_LT(after_trip.size(), after_wait.size() * 5 / 4);
  // The film that ran off while the car was away is counted as drained as it left: the rings
  // hold as much as the waiting car's but for that.
  EXPECT_GT(in_rings(trip), 0.7 * in_rings(wait));
}

TEST_F(RoadWaterTest, TheRainFallsOnTheRoadTheCarLeftBehind) {
  // A minute of rain, then one car goes 600 m away for two minutes of rain and comes back while
  // another waits: the road the first one left took the rain as the waiting car's did.
  RoadWater trip(surface), wait(surface);
  const double s0 = 150.0;
  stand({&trip, &wait}, at(s0, 0.0), 30.0, 600, 0.1);
  for (int k = 0; k < 1200; ++k) {
    const double s = k < 30 ? s0 + 20.0 * k : k >= 1170 ? s0 + 20.0 * (1200 - k) : s0 + 600.0;
    trip.step(at(s, 0.0), 30.0, 0.1);
    wait.step(at(s0, 0.0), 30.0, 0.1);
  }
  stand({&trip, &wait}, at(s0, 0.0), 30.0, 300, 0.1);
  const std::set<Cell> came_back = puddles(trip, 1), waited = puddles(wait, 1);
  const int both = common(came_back, waited);
  std::printf(
      "water in the rings %.4f against %.4f m^3; puddle cells %zu against %zu, %d in both\n",
      in_rings(trip), in_rings(wait), came_back.size(), waited.size(), both);
  EXPECT_NEAR(in_rings(trip), in_rings(wait), 0.1 * in_rings(wait));
  ASSERT_FALSE(waited.empty());
  EXPECT_GT(both, static_cast<int>(waited.size()) * 7 / 10);
}

TEST_F(RoadWaterTest, PuddlesAreThereAheadOfACarAt30MetresASecond) {
  // After 5 minutes of rain a car sets off at 30 m/s; another stands further on all along. As the
  // first one arrives, its finest ring holds water where the other's has its puddles: the coarse
  // rings ahead kept what the ruts and bowls hold, and shared it out to them as they came near.
  RoadWater moving(surface), standing(surface);
  const double s0 = 150.0, s1 = 450.0;
  for (int k = 0; k < 3000; ++k) {
    moving.step(at(s0, track.lane_centre(0)), 30.0, 0.1);
    standing.step(at(s1, track.lane_centre(0)), 30.0, 0.1);
  }
  for (int k = 1; k <= 300; ++k) {  // 10 s at 30 fps
    moving.step(at(s0 + k * 1.0, track.lane_centre(0)), 30.0, 1.0 / 30.0);
    standing.step(at(s1, track.lane_centre(0)), 30.0, 1.0 / 30.0);
  }
  const std::set<Cell> arrived = puddles(moving, 1), there = puddles(standing, 1);
  ASSERT_EQ(moving.origin(0), standing.origin(0));
  double in_there = 0.0, arrived_in_there = 0.0, arrived_elsewhere = 0.0;
  int elsewhere = 0, both = 0;
  const int n = moving.cells();
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const std::size_t c = static_cast<std::size_t>(j) * n + i;
      if (!moving.paved()[c]) continue;
      const Cell cell{0, moving.origin(0).x + i, moving.origin(0).y + j};
      const double a = std::max(moving.water()[c] - moving.config().capacity_m, 0.0);
      if (there.count(cell)) {
        in_there += standing.water()[c] - standing.config().capacity_m;
        arrived_in_there += a;
        both += arrived.count(cell);
      } else {
        arrived_elsewhere += a;
        ++elsewhere;
      }
    }
  }
  ASSERT_FALSE(there.empty());
  in_there /= there.size(), arrived_in_there /= there.size(), arrived_elsewhere /= elsewhere;
  std::printf(
      "the standing car's %zu puddle cells: %.2f mm standing there, %.2f mm for the car arriving "
      "at 30 m/s (%.2f mm on its other cells); its %zu puddle cells, %d of them the standing "
      "car's\n",
      there.size(), in_there * 1e3, arrived_in_there * 1e3, arrived_elsewhere * 1e3, arrived.size(),
      both);
  EXPECT_GT(arrived_in_there, 0.4 * in_there);
  EXPECT_GT(arrived_in_there, 2.5 * arrived_elsewhere);
  EXPECT_FALSE(arrived.empty());
  EXPECT_GE(both, static_cast<int>(arrived.size()) * 8 / 10);
}

TEST_F(RoadWaterTest, TheRingsMeetWithoutASeam) {
  // Two and a half minutes of rain on the rings and on one window of the finest cells 64 m wide.
  // Across the paved width, in strips just inside the first two rings' borders and just outside
  // them, the rings hold what the fine window holds there: no step where they meet.
  RoadWater rings(surface);
  RoadWaterConfig fine_config;
  fine_config.levels = 1;
  fine_config.cells = 256;
  RoadWater fine(surface, fine_config);
  const double s0 = 250.0;
  for (int k = 0; k < 1500; ++k) {
    rings.step(at(s0, track.lane_centre(0)), 30.0, 0.1);
    fine.step(at(s0, track.lane_centre(0)), 30.0, 0.1);
  }
  const double half_width = track.paved_half_width();
  for (int l = 0; l < 2; ++l) {
    const double half = 0.5 * rings.cells() * rings.cell_m(l);
    for (const double sign : {-1.0, 1.0}) {
      for (const double side : {-1.0, 1.0}) {  // inside, outside
        double got = 0.0, want = 0.0;
        for (double lateral = -half_width + 0.1; lateral < half_width; lateral += 0.05) {
          for (double d = 0.25; d < 3.0; d += 0.25) {
            const glm::dvec2 p = at(s0 + sign * (half + side * (1.0 + d)), lateral);
            got += rings.water_m(p);
            want += fine.water_m(p);
          }
        }
        std::printf("ring %d's border %s, %s: %.3f of the fine window's water\n", l,
                    sign < 0.0 ? "behind" : "ahead", side < 0.0 ? "inside" : "outside", got / want);
        EXPECT_NEAR(got / want, 1.0, 0.1) << "ring " << l;
      }
    }
  }
}

TEST_F(RoadWaterTest, TheSameInputsGiveTheSameWater) {
  RoadWater a(surface), b(surface);
  const RoadSurface other_surface(track, 8);
  RoadWater c(other_surface);
  for (int k = 0; k < 900; ++k) {  // 90 s of 40 mm/h, the car creeping on at 0.5 m/s
    const glm::dvec2 car = at(100.0 + 0.05 * k, -1.75);
    a.step(car, 40.0, 0.1);
    b.step(car, 40.0, 0.1);
    c.step(car, 40.0, 0.1);
  }
  EXPECT_EQ(a.water(), b.water());
  EXPECT_NE(a.water(), c.water());
}

TEST_F(RoadWaterTest, TheImageForTheRendererIsTheRingsInMillimetres) {
  RoadWater water(surface);
  RoadWaterImage before;  // before the first step: the rings' size, all dry
  water.image(before);
  ASSERT_TRUE(before.complete());
  EXPECT_EQ(*std::max_element(before.water_standing_mm.begin(), before.water_standing_mm.end()),
            0.0f);
  for (int k = 0; k < 600; ++k) water.step(at(250.0, -1.75), 30.0, 0.1);  // a minute of 30 mm/h
  RoadWaterImage image;
  water.image(image);
  const int n = water.cells();
  ASSERT_TRUE(image.complete());
  ASSERT_EQ(image.cells, n);
  ASSERT_EQ(image.levels, water.levels());
  const std::size_t per_level = static_cast<std::size_t>(n) * n;
  ASSERT_EQ(image.water_standing_mm.size(), per_level * water.levels() * 2);
  double sum = 0.0, paved_area = 0.0, max_standing = 0.0;
  int edge = 0, covered = 0;
  for (int l = 0; l < water.levels(); ++l) {
    EXPECT_EQ(image.origins[l], water.origin(l));
    const double a = water.cell_m(l) * water.cell_m(l);
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        const std::size_t c = l * per_level + static_cast<std::size_t>(j) * n + i;
        const float* px = &image.water_standing_mm[2 * c];
        if (!water.owned()[c]) {
          // In a finer ring: the mean of the four finer cells.
          ++covered;
          const glm::ivec2 d = 2 * (water.origin(l) + glm::ivec2(i, j)) - water.origin(l - 1);
          float mean = 0.0f;
          for (int k = 0; k < 4; ++k)
            mean += 0.25f * image.water_standing_mm[2 * ((l - 1) * per_level +
                                                         (d.y + (k >> 1)) * n + d.x + (k & 1))];
          EXPECT_NEAR(px[0], mean, 1e-4f * (1.0f + mean));
          continue;
        }
        const double w = water.sheet_m(c) * 1e3;
        const double standing =
            std::max(water.water()[c] * 1e3 - water.config().capacity_m * 1e3, 0.0);
        if (water.paved()[c]) {
          EXPECT_NEAR(px[0], w, 1e-4 * (1.0 + w));
          EXPECT_NEAR(px[1], standing, 1e-4 * (1.0 + standing));
          sum += w * a;
          paved_area += a;
          max_standing = std::max(max_standing, standing);
        } else if (px[0] > 0.0f) {
          ++edge;  // beside the road: its neighbours' water, so that the road's edge draws smooth
          EXPECT_EQ(water.water()[c], 0.0);
        }
      }
    }
  }
  ASSERT_GT(paved_area, 0.0);
  EXPECT_GT(edge, 0);
  EXPECT_EQ(covered, static_cast<int>(per_level / 4) * (water.levels() - 1));
  EXPECT_NEAR(image.mean_water_mm, sum / paved_area, 1e-4 * sum / paved_area);
  EXPECT_NEAR(image.max_standing_mm, max_standing, 1e-4 * (1.0 + max_standing));
  EXPECT_GT(image.mean_water_mm, 0.25);  // a minute of 30 mm/h is 0.5 mm
  // A lookup finds the finest cell: where the model's own lookup does.
  for (const double ahead : {0.0, 6.0, 12.0, 30.0, 60.0}) {
    const glm::dvec2 p = at(250.0 + ahead, -1.75);
    EXPECT_NEAR(image.at(p).y, water.standing_m(p) * 1e3, 1e-4 * (1.0 + water.standing_m(p) * 1e3))
        << ahead << " m ahead";
  }
  EXPECT_EQ(image.at(at(450.0, -1.75)).x, image.mean_water_mm);  // past the last ring
}

// The renderer finds a point's two rings from its distance to the finest window's middle
// (RoadWaterImage::reach_m, road_surface.glsl's water_at): the finest window whose reach the point
// lies within, and the next. That holds wherever the car is: every window nearer than the first
// holds no point of it, and where the first does not hold it, the next holds it past its fading
// band (4 cells), as a lookup that tries every ring would find.
TEST(RoadWaterImageTest, TheFinestRingThatMayHoldAPointAndTheNextAreAllItNeeds) {
  const RoadWaterConfig config;
  RoadWaterImage image;
  image.cell_m = config.cell_m;
  image.cells = config.cells;
  image.levels = config.levels;
  std::uint32_t seed = 12345u;
  auto uniform = [&](double lo, double hi) {
    seed = seed * 1664525u + 1013904223u;
    return lo + (hi - lo) * static_cast<double>(seed >> 8) / static_cast<double>(1u << 24);
  };
  // How far inside window l a point lies, in its cells (negative outside).
  auto inside_cells = [&](int l, glm::dvec2 p) {
    const double cell = image.level_cell_m(l);
    const glm::dvec2 u = p / cell - glm::dvec2(image.origins[l]);
    return std::min({u.x, u.y, image.cells - u.x, image.cells - u.y});
  };
  int first_holds = 0, next_holds = 0, past_all = 0;
  for (int car = 0; car < 400; ++car) {
    const glm::dvec2 centre(uniform(-5000.0, 5000.0), uniform(-5000.0, 5000.0));
    image.origins = RoadWater::ring_origins(centre, image.cell_m, image.cells, image.levels);
    const glm::dvec2 middle0 = (glm::dvec2(image.origins[0]) + 0.5 * image.cells) * image.cell_m;
    for (int k = 0; k < 200; ++k) {
      const glm::dvec2 p = centre + glm::dvec2(uniform(-150.0, 150.0), uniform(-150.0, 150.0));
      const glm::dvec2 off(std::abs(p.x - middle0.x), std::abs(p.y - middle0.y));
      int first = 0;
      while (first < image.levels && std::max(off.x, off.y) >= image.reach_m(first)) ++first;
      for (int l = 0; l < first; ++l)
        ASSERT_LE(inside_cells(l, p), 0.0) << "window " << l << " holds a point past its reach";
      if (first == image.levels) {
        ++past_all;
        continue;
      }
      if (inside_cells(first, p) > 0.0) {
        ++first_holds;
      } else if (first + 1 < image.levels) {
        ASSERT_GE(inside_cells(first + 1, p), 4.0) << "in window " << first + 1 << "'s band";
        ++next_holds;
      }
    }
  }
  // (Each case met many times.)
  EXPECT_GT(first_holds, 1000);
  EXPECT_GT(next_holds, 300);
  EXPECT_GT(past_all, 1000);
}

}  // namespace
}  // namespace downpour::sim
