// Spray from tires and puddles: none on a dry road; more with speed and with water; droplet sizes
// by the road's state as in the paper's table 1, splashes only from puddles; the mudguard's arc;
// the water taken and given back closes both ledgers; the budget; the same inputs give the same
// spray; a truck's spray hangs behind it at its height; following it wets the ego car's glass.
#include "server/sim/spray.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include "server/sim/pose.hpp"
#include "server/sim/road_surface.hpp"
#include "server/sim/road_water.hpp"
#include "server/sim/simulation.hpp"
#include "server/sim/track.hpp"
#include "server/sim/vehicle_class.hpp"
#include "tests/support/spray_drive.hpp"

namespace downpour::sim {
namespace {

// A road with the same water everywhere, that never runs dry: it counts what is taken and given.
class EvenGround final : public SprayGround {
 public:
  explicit EvenGround(double water_m) : water_m_(water_m) {}
  Probe probe(glm::dvec2) const override {
    RoadWaterConfig thresholds;
    Probe p;
    p.water_m = water_m_;
    p.standing_m = std::max(water_m_ - thresholds.capacity_m, 0.0);
    p.state = road_state(water_m_, thresholds);
    return p;
  }
  double take(glm::dvec2, double volume_m3) override { return taken += volume_m3, volume_m3; }
  double give(glm::dvec2, double volume_m3) override { return given += volume_m3, volume_m3; }
  double taken = 0.0, given = 0.0;

 private:
  double water_m_;
};

constexpr double kWetM = 0.0003;     // in the texture only
constexpr double kDrenchM = 0.0008;  // a 0.3 mm film
constexpr double kPuddleM = 0.004;   // 3.5 mm standing

const Track& track() { return Track::built_in(); }

using testing::on_track;

const glm::dvec3 kTruck = testing::kTruckSize;

// Drives the sources along the track for `seconds` (each keeps its speed) over `ground`.
struct Drive {
  Spray spray;
  std::vector<SpraySource> sources;
  std::vector<double> s, speed;
  explicit Drive(std::uint64_t seed = 7, SprayConfig config = {}) : spray(seed, config) {}
  void add(std::uint32_t key, double s0, double v, glm::dvec3 size = {4.5, 1.8, 1.47}) {
    sources.push_back({key, on_track(s0, v), size});
    s.push_back(s0);
    speed.push_back(v);
  }
  void run(double seconds, SprayGround& ground) {
    const int steps = static_cast<int>(std::lround(seconds / spray.config().step_s));
    for (int k = 0; k < steps; ++k) {
      for (std::size_t i = 0; i < sources.size(); ++i) {
        s[i] += speed[i] * spray.config().step_s;
        sources[i].state = on_track(s[i], speed[i]);
      }
      spray.step(sources, glm::dvec3(0.0), ground);
    }
  }
};

struct Thrown {
  double volume_m3 = 0.0;  // taken from the road
  std::size_t parcels = 0;
};

Thrown thrown(double water_m, double speed, double seconds = 1.0) {
  EvenGround ground(water_m);
  Drive drive;
  drive.add(0, 100.0, speed);
  drive.run(seconds, ground);
  return {ground.taken, drive.spray.particles().size()};
}

TEST(SprayTest, NoneOnADryRoad) {
  EvenGround ground(0.0);
  Drive drive;
  drive.add(0, 100.0, 30.0);
  drive.add(1, 130.0, 30.0, kTruck);
  drive.run(2.0, ground);
  EXPECT_TRUE(drive.spray.particles().empty());
  EXPECT_EQ(ground.taken, 0.0);
}

TEST(SprayTest, MoreWithSpeedAndWithWater) {
  const Thrown slow = thrown(kDrenchM, 10.0), mid = thrown(kDrenchM, 20.0),
               fast = thrown(kDrenchM, 30.0);
  std::printf(
      "drenched road, 1 s: %.3f / %.3f / %.3f litres, %zu / %zu / %zu parcels at 10 / 20 "
      "/ 30 m/s\n",
      slow.volume_m3 * 1e3, mid.volume_m3 * 1e3, fast.volume_m3 * 1e3, slow.parcels, mid.parcels,
      fast.parcels);
  EXPECT_LT(slow.volume_m3, mid.volume_m3);
  EXPECT_LT(mid.volume_m3, fast.volume_m3);
  EXPECT_LT(slow.parcels, fast.parcels);

  const Thrown wet = thrown(kWetM, 25.0), drench = thrown(kDrenchM, 25.0),
               puddle = thrown(kPuddleM, 25.0);
  std::printf(
      "25 m/s, 1 s: %.3f / %.3f / %.3f litres, %zu / %zu / %zu parcels on wet / drenched "
      "/ puddled road\n",
      wet.volume_m3 * 1e3, drench.volume_m3 * 1e3, puddle.volume_m3 * 1e3, wet.parcels,
      drench.parcels, puddle.parcels);
  EXPECT_GT(wet.volume_m3, 0.0);
  EXPECT_LT(wet.volume_m3, drench.volume_m3);
  EXPECT_LT(drench.volume_m3, puddle.volume_m3);
  EXPECT_LT(wet.parcels, drench.parcels);
  EXPECT_LT(drench.parcels, puddle.parcels);
}

// Table 1: small droplets from a wet road, medium from a drenched one, large from puddles (with
// splashes from the ground); only puddles' droplets land back as water.
TEST(SprayTest, DropletSizesFollowTheRoadAndOnlyPuddlesSplash) {
  struct Case {
    double water_m;
    SprayKind kind;
    bool splashes;
  };
  for (const Case& c :
       {Case{kWetM, SprayKind::kSmall, false}, Case{kDrenchM, SprayKind::kMedium, false},
        Case{kPuddleM, SprayKind::kLarge, true}}) {
    EvenGround ground(c.water_m);
    Drive drive;
    drive.add(0, 100.0, 25.0);
    drive.run(1.5, ground);
    int splashes = 0, others = 0;
    for (const SprayParticle& p : drive.spray.particles()) {
      splashes += p.splash;
      if (p.kind != SprayKind::kMist && p.kind != c.kind) ++others;
    }
    SCOPED_TRACE(c.water_m);
    EXPECT_EQ(others, 0);
    EXPECT_EQ(splashes > 0, c.splashes);
    EXPECT_EQ(ground.given > 0.0, c.splashes);
  }
}

// Tire parcels are born on the arc below the mudguard: no higher than the wheel's centre less
// R cos(mudguard) (the guard blocks the rest).
TEST(SprayTest, TheMudguardBlocksTheUpperArc) {
  EvenGround ground(kDrenchM);
  Drive drive;
  drive.add(0, 100.0, 25.0);
  double highest = 0.0;
  int born = 0;
  for (int k = 0; k < 60; ++k) {
    drive.run(drive.spray.config().step_s, ground);
    const double ground_z = drive.sources[0].state.position_m.z;
    for (const SprayParticle& p : drive.spray.particles()) {
      if (p.age_s > 0.0f || p.splash) continue;
      highest = std::max(highest, p.position_m.z - ground_z);
      ++born;
    }
  }
  const SprayConfig& c = drive.spray.config();
  const double limit = c.tire_radius_m * (1.0 - std::cos(c.mudguard_deg * M_PI / 180.0));
  std::printf("%d parcels born, the highest %.3f m above the road (the guard's edge %.3f m)\n",
              born, highest, limit);
  EXPECT_GT(born, 100);
  EXPECT_LE(highest, limit + 1e-6);
  EXPECT_GT(highest, 0.5 * limit);
}

// The spray takes water from the road's cells and puddles' droplets give some back: the road's
// ledger still closes, and the spray's own: all it threw is in the air or accounted for.
TEST(SprayTest, BothLedgersClose) {
  auto surface = std::make_shared<const RoadSurface>(track(), 3);
  RoadWaterConfig config;
  config.initial_m = 0.0035;  // puddles everywhere at first; they run into the hollows
  RoadWater road(*surface, config);
  RoadWaterGround ground(road);
  Drive drive;
  drive.add(0, 200.0, 25.0);
  drive.add(1, 225.0, 25.0, kTruck);
  drive.add(2, 260.0, 20.0);
  const int steps = 8 * 60;  // 8 s
  for (int k = 0; k < steps; ++k) {
    if (k % 2 == 0) road.step(glm::dvec2(drive.sources[0].state.position_m), 30.0, 1.0 / 30.0);
    drive.run(drive.spray.config().step_s, ground);
  }
  const RoadWater::Ledger& l = road.ledger();
  const double road_in = l.rain_in_m3 + l.returned_m3;
  const double road_out = road.stored_m3() + l.drained_m3 + l.evaporated_m3 + l.thrown_m3;
  const SprayLedger& s = drive.spray.ledger();
  const double spray_in = s.taken_m3 + s.beyond_m3;
  const double spray_out = drive.spray.airborne_m3() + s.returned_m3 + s.landed_m3 + s.on_glass_m3 +
                           s.on_body_m3 + s.dispersed_m3 + s.dropped_m3;
  std::printf(
      "road: in %.4f m^3 (returned %.5f), out %.4f (thrown %.5f); spray: taken %.5f, "
      "beyond %.5f, airborne %.5f, returned %.5f, landed %.5f, dispersed %.5f, dropped "
      "%.5f\n",
      road_in, l.returned_m3, road_out, l.thrown_m3, s.taken_m3, s.beyond_m3,
      drive.spray.airborne_m3(), s.returned_m3, s.landed_m3, s.dispersed_m3, s.dropped_m3);
  EXPECT_GT(l.thrown_m3, 0.0);
  EXPECT_GT(l.returned_m3, 0.0);
  EXPECT_NEAR(l.thrown_m3, s.taken_m3, 1e-12);
  EXPECT_NEAR(l.returned_m3, s.returned_m3, 1e-12);
  EXPECT_NEAR(road_out, road_in, 1e-9 * road_in);
  EXPECT_NEAR(spray_out, spray_in, 1e-9 * spray_in);
}

TEST(SprayTest, TheBudgetLetsTheOldestGo) {
  SprayConfig config;
  config.max_particles = 800;
  EvenGround ground(kPuddleM);
  Drive drive(7, config);
  for (std::uint32_t i = 0; i < 6; ++i) drive.add(i, 100.0 + 15.0 * i, 25.0, kTruck);
  std::size_t most = 0;
  for (int k = 0; k < 120; ++k) {
    drive.run(config.step_s, ground);
    most = std::max(most, drive.spray.particles().size());
  }
  EXPECT_EQ(most, 800u);
  EXPECT_GT(drive.spray.ledger().dropped_m3, 0.0);
  // What is left is the newest: no parcel older than what 800 of a full stream's can be.
  float oldest = 0.0f;
  for (const SprayParticle& p : drive.spray.particles()) oldest = std::max(oldest, p.age_s);
  EXPECT_LT(oldest, 0.5f);
}

TEST(SprayTest, TheSameInputsGiveTheSameSpray) {
  auto run = [](std::uint64_t seed) {
    EvenGround ground(kPuddleM);
    Drive drive(seed);
    drive.add(0, 100.0, 25.0);
    drive.add(5, 125.0, 25.0, kTruck);
    drive.run(1.0, ground);
    return drive.spray.particles();
  };
  const auto a = run(11), b = run(11), c = run(12);
  ASSERT_FALSE(a.empty());
  ASSERT_FALSE(c.empty());
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].position_m, b[i].position_m);
    EXPECT_EQ(a[i].volume_m3, b[i].volume_m3);
  }
  EXPECT_NE(a.size() == c.size() && a.front().position_m == c.front().position_m, true);
}

// Behind a truck at 25 m/s on a drenched road the spray rises to its height and hangs in its
// wake: parcels more than 1.5 m up from 5 to 30 m behind it.
TEST(SprayTest, ATrucksSprayHangsBehindIt) {
  EvenGround ground(kDrenchM);
  Drive drive;
  drive.add(1, 300.0, 25.0, kTruck);
  drive.run(3.0, ground);
  const VehicleState& truck = drive.sources[0].state;
  const glm::dvec3 forward(std::cos(truck.rotation.yaw_deg * M_PI / 180.0),
                           std::sin(truck.rotation.yaw_deg * M_PI / 180.0), 0.0);
  int high = 0, behind = 0;
  double top = 0.0;
  for (const SprayParticle& p : drive.spray.particles()) {
    const double back = -glm::dot(p.position_m - truck.position_m, forward);
    if (back < 5.0 || back > 30.0) continue;
    ++behind;
    const double up = p.position_m.z - truck.position_m.z;
    top = std::max(top, up);
    high += up > 1.5;
  }
  std::printf("5-30 m behind the truck: %d parcels, %d above 1.5 m, the highest %.2f m\n", behind,
              high, top);
  EXPECT_GT(behind, 200);
  EXPECT_GT(high, 20);
}

// Following a truck at 25 m/s on a drenched road wets the ego car's windshield; alone, on the
// same road in the same (light) rain, it stays far drier.
TEST(SprayTest, FollowingATruckWetsTheGlass) {
  auto glass = [](bool follow) {
    testing::SprayDrive d;
    d.road_water_m = kDrenchM;
    if (follow) d.truck_gap_m = 22.0;
    const Simulation sim = testing::drive(d);
    const SprayLedger& l = sim.spray().ledger();
    std::printf("%s: glass wet fraction %.4f, %.2f ml of spray on it, %zu parcels\n",
                follow ? "following a truck" : "alone", sim.state().windshield.glass_wet_fraction,
                l.on_glass_m3 * 1e6, sim.spray().particles().size());
    return std::make_pair(sim.state().windshield.glass_wet_fraction, l.on_glass_m3);
  };
  const auto [alone, alone_ml] = glass(false);
  const auto [following, following_ml] = glass(true);
  EXPECT_GT(following_ml, 0.0);
  EXPECT_GT(following, alone + 0.02);
}

// A car 20 m behind a truck at 25 m/s on a drenched road: the truck's spray that meets the car
// stops there (none of it is left inside its body, where parcels pass when it is not there) and
// wets it;
// the truck, which meets none, stays dry.
TEST(SprayTest, AVehicleStopsTheSprayThatMeetsItAndGetsWet) {
  constexpr double kGap = 20.0;
  const glm::dvec3 car(4.5, 1.8, 1.47);
  auto run = [&](bool with_car, double seconds) {
    EvenGround ground(kDrenchM);
    Drive drive;
    drive.add(1, 300.0, 25.0, kTruck);
    if (with_car) drive.add(2, 300.0 - kGap, 25.0, car);
    drive.run(seconds, ground);
    // Parcels within the car's body (where it is, or would be): its box in its own frame.
    const VehicleState at = on_track(300.0 - kGap + 25.0 * seconds, 25.0);
    const glm::dmat3 to_car = glm::transpose(rotation_matrix(at.rotation));
    const VehicleLayout& layout = vehicle_layout(VehicleClass::kCar);
    int inside = 0;
    for (const SprayParticle& p : drive.spray.particles()) {
      if (p.source == 2) continue;  // its own front wheels' spray passes under its wings
      const glm::dvec3 q = to_car * (p.position_m - at.position_m);
      inside += q.x > layout.rear_m + 0.3 && q.x < layout.rear_m + car.x - 0.3 &&
                std::abs(q.y) < 0.5 * car.y - 0.2 && q.z > 0.3 && q.z < car.z - 0.2;
    }
    return std::make_tuple(inside, drive.spray.body_wetness(2, car),
                           drive.spray.body_wetness(1, kTruck), drive.spray.ledger().on_body_m3);
  };
  const auto [passing, no_car, no_car_truck, no_car_ml] = run(false, 3.0);
  const auto [stopped, wet, truck_wet, caught_m3] = run(true, 3.0);
  const auto [early_stopped, early_wet, early_truck, early_m3] = run(true, 0.5);
  std::printf(
      "parcels in the car's place: %d without it, %d with it; its body caught %.1f ml, wet %.2f "
      "after 3 s (%.2f after 0.5 s); the truck wet %.2f\n",
      passing, stopped, caught_m3 * 1e6, wet, early_wet, truck_wet);
  EXPECT_GT(passing, 20);
  EXPECT_EQ(stopped, 0);
  EXPECT_EQ(no_car, 0.0);
  EXPECT_GT(wet, 0.8);
  EXPECT_LT(early_wet, wet);
  EXPECT_EQ(truck_wet, 0.0);
}

// Body or spray (the image's classification, a hash of cells) is what counting every pair gives: a
// liquid parcel with at least body_neighbours others within neighbour_radius_m is body. Behind a
// truck on a puddled road for 2 s.
TEST(SprayTest, BodyOrSprayIsWhatCountingEveryPairGives) {
  EvenGround ground(kPuddleM);
  Drive drive;
  drive.add(1, 300.0, 25.0, kTruck);
  drive.run(2.0, ground);
  SprayImage image;
  drive.spray.image(glm::dvec3(0.0), image);
  const SprayConfig& c = drive.spray.config();
  const float h2 = static_cast<float>(c.neighbour_radius_m * c.neighbour_radius_m);
  int body = 0, liquid = 0, wrong = 0;
  for (const SprayImage::Point& p : image.points) {
    if (p.kind == SprayKind::kMist) continue;
    ++liquid;
    int near = -1;  // itself
    for (const SprayImage::Point& o : image.points) {
      if (o.kind == SprayKind::kMist) continue;
      const float ex = o.x - p.x, ey = o.y - p.y, ez = o.z - p.z;
      near += ex * ex + ey * ey + ez * ez <= h2;
    }
    const bool is_body = near >= c.body_neighbours;
    body += is_body;
    wrong += is_body != p.body;
  }
  std::printf("%d liquid parcels, %d of them body; %d classified otherwise than by every pair\n",
              liquid, body, wrong);
  EXPECT_GT(body, 100);
  EXPECT_GT(liquid - body, 100);
  EXPECT_EQ(wrong, 0);
}

// What a body caught runs off and dries once the spray stops: with no spray, a wet body's water
// keeps exp(-t / body_dry_s) of itself.
TEST(SprayTest, AWetBodyDries) {
  EvenGround drenched(kDrenchM), dry(0.0);
  SprayConfig config;
  config.wet_film_mm *= 10.0;  // (so that it is not wet through, where its wetness stops at 1)
  Drive drive(7, config);
  drive.add(1, 300.0, 25.0, kTruck);
  drive.add(2, 280.0, 25.0);
  drive.run(3.0, drenched);
  const glm::dvec3 car(4.5, 1.8, 1.47);
  drive.run(3.0, dry);  // the last of the spray settles
  const double before = drive.spray.body_wetness(2, car);
  const double seconds = 0.5 * drive.spray.config().body_dry_s;
  drive.run(seconds, dry);
  const double after = drive.spray.body_wetness(2, car);
  std::printf("wet %.3f, then %.3f after %.0f s without spray\n", before, after, seconds);
  ASSERT_GT(before, 0.0);
  ASSERT_LT(before, 1.0);
  EXPECT_NEAR(after / before, std::exp(-0.5), 0.01);
}

}  // namespace
}  // namespace downpour::sim
