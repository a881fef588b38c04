// The windshield water model (seed 000): invariants of the mesh and particle models, their
// switching, rain arrival and determinism.
#include "server/sim/water.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include "server/sim/blade_sweep.hpp"
#include "server/sim/mesh_model.hpp"
#include "server/sim/particle_model.hpp"
#include "server/sim/random.hpp"
#include "server/sim/scenario.hpp"
#include "server/sim/simulation.hpp"
#include "server/sim/wipers.hpp"

namespace downpour::sim {
namespace {

constexpr double kDt = 1.0 / 120.0;

WaterInputs still_inputs(const WiperConfig& wipers = {}) {
  WaterInputs in;
  const WiperMotion parked(wipers);
  in.blades_before = in.blades_after = parked.poses();
  return in;
}

double ledger_total(const WaterSim& w) {
  const WaterLedger& l = w.ledger();
  return w.mass_on_glass() + l.wiped_off + l.drained + l.evaporated;
}

TEST(WaterTest, DropRadiusIsASphericalCapOfTheMass) {
  EXPECT_NEAR(drop_radius_mm(drop_mass_mg(2.2)), 2.2, 1e-12);
  // A cap at 40 degrees: height a tan(20 deg), volume pi h (3 a^2 + h^2) / 6.
  const double h = std::tan(20.0 * M_PI / 180.0);
  EXPECT_NEAR(drop_mass_mg(1.0), M_PI * h * (3.0 + h * h) / 6.0, 1e-12);
  // Atlas et al.: about 4.0, 6.5, 8.0 m/s at 1, 2, 3 mm.
  EXPECT_NEAR(terminal_speed_mps(1.0), 4.0, 0.1);
  EXPECT_NEAR(terminal_speed_mps(2.0), 6.5, 0.1);
  EXPECT_NEAR(terminal_speed_mps(3.0), 8.0, 0.1);
}

TEST(WaterTest, ADropBelowTheCriticalSizeStaysPut) {
  WaterSim water({}, 1);
  const glm::dvec2 at(700.0, 400.0);
  ASSERT_TRUE(water.add_drop(at, drop_mass_mg(2.1)));
  for (int i = 0; i < 600; ++i) water.step(kDt, still_inputs());  // 5 s
  ASSERT_EQ(water.drop_count(), 1u);
  EXPECT_GE(water.drop_at(at), 0);
  EXPECT_FALSE(water.drops()[water.drop_at(at)].moving);
}

TEST(WaterTest, ADropAboveTheCriticalSizeRunsDownAndLeavesATrail) {
  WaterSim water({}, 1);
  const glm::dvec2 at(700.0, 600.0);
  ASSERT_TRUE(water.add_drop(at, drop_mass_mg(3.0)));
  for (int i = 0; i < 240; ++i) water.step(kDt, still_inputs());  // 2 s
  int main = -1;
  std::size_t trails = 0;
  for (std::size_t i = 0; i < water.drops().size(); ++i) {
    const auto& d = water.drops()[i];
    if (!d.alive) continue;
    if (d.trail) {
      ++trails;
    } else {
      main = static_cast<int>(i);
    }
  }
  ASSERT_GE(main, 0);
  const auto& d = water.drops()[main];
  EXPECT_LT(d.pos.y, at.y - 20.0) << "it ran down";
  EXPECT_LT(std::abs(d.pos.x - at.x), at.y - d.pos.y) << "mostly down, meandering";
  EXPECT_GT(trails, 3u);
  EXPECT_NEAR(ledger_total(water), water.ledger().arrived, 1e-9);
}

TEST(WaterTest, TrailDropsShrinkAndVanish) {
  WaterSim water({}, 3);
  ASSERT_TRUE(water.add_drop({700.0, 700.0}, drop_mass_mg(3.0)));
  for (int i = 0; i < 120; ++i) water.step(kDt, still_inputs());
  const double evaporated_early = water.ledger().evaporated;
  // Long after the trail lifetime the trails of the first second are gone, their water counted as
  // evaporated; any trail left is younger than the lifetime (the drop, just over the critical size
  // now, still creeps and leaves one now and then).
  for (int i = 0; i < 120 * 30; ++i) water.step(kDt, still_inputs());
  const double lifetime = WaterConfig{}.trail_lifetime_s;
  for (const auto& d : water.drops()) EXPECT_FALSE(d.alive && d.trail && d.age >= lifetime);
  EXPECT_GT(water.ledger().evaporated, evaporated_early);
  EXPECT_NEAR(ledger_total(water), water.ledger().arrived, 1e-9);
}

TEST(WaterTest, AMovingDropFusesWithTheDropItMeets) {
  WaterSim water({}, 5);
  const glm::dvec2 below(700.0, 300.0);
  ASSERT_TRUE(water.add_drop(below, drop_mass_mg(2.0)));  // static
  const int small = water.drop_at(below);
  const double small_mass = water.drops()[small].mass;
  ASSERT_TRUE(water.add_drop(below + glm::dvec2(0.0, 16.0), drop_mass_mg(4.0)));  // flows
  ASSERT_EQ(water.drop_count(), 2u);
  int steps = 0;
  while (water.drops()[small].alive && water.drop_at(below) == small && steps++ < 120 * 4) {
    water.step(kDt, still_inputs());
  }
  // The small drop's water is now in the big one (less what that left in trails on the way).
  double largest = 0.0;
  for (const auto& d : water.drops()) {
    if (d.alive && !d.trail) largest = std::max(largest, d.mass);
  }
  EXPECT_LT(steps, 120 * 4) << "the drops never met";
  EXPECT_GT(largest, 0.8 * drop_mass_mg(4.0) + small_mass);
  EXPECT_NEAR(ledger_total(water), water.ledger().arrived, 1e-9);
}

TEST(WaterTest, TouchingDropsRunTogether) {
  WaterSim water({}, 5);
  ASSERT_TRUE(water.add_drop({700.0, 300.0}, drop_mass_mg(1.5)));
  ASSERT_TRUE(water.add_drop({702.5, 300.0}, drop_mass_mg(1.5)));  // circles overlap
  EXPECT_EQ(water.drop_count(), 1u);
  EXPECT_NEAR(water.mass_on_glass(), 2.0 * drop_mass_mg(1.5), 1e-9);
}

TEST(WaterTest, AirflowAtSpeedPushesDropsUpTheGlass) {
  WaterSim water({}, 7);
  const glm::dvec2 at(760.0, 300.0);
  ASSERT_TRUE(water.add_drop(at, drop_mass_mg(2.0)));  // below critical: still when parked
  WaterInputs in = still_inputs();
  in.air_velocity_mps = {-30.0, 0.0, 0.0};  // 108 km/h, no wind
  EXPECT_GT(water.drive_per_pin(2.0, in).y, 1.0);
  for (int i = 0; i < 240; ++i) water.step(kDt, in);
  double highest = 0.0;
  for (const auto& d : water.drops()) {
    if (d.alive && !d.trail) highest = std::max(highest, d.pos.y);
  }
  EXPECT_GT(highest, at.y + 20.0);
}

TEST(WaterTest, FasterDrivingCollectsMoreRain) {
  auto collected = [](double speed) {
    WaterSim water({}, 11);
    WaterInputs in = still_inputs();
    in.rain_rate_mm_h = 10.0;
    in.air_velocity_mps = {-speed, 0.0, 0.0};
    for (int i = 0; i < 240; ++i) water.step(kDt, in);
    return water.ledger().arrived;
  };
  const double parked = collected(0.0), slow = collected(10.0), fast = collected(30.0);
  EXPECT_GT(parked, 0.0);
  EXPECT_GT(slow, 1.3 * parked);
  EXPECT_GT(fast, 1.6 * slow);  // the flux through the glass doubles from 10 to 30 m/s
}

TEST(WaterTest, ParticlesDoNotOverlapAfterAStep) {
  WaterSim water({}, 13);
  const double r = water.config().water.particle_radius_mm;
  // A tight cluster inside blade 0's region, with the blade turning slowly so the region holds.
  WiperMotion wipers(water.config().wipers);
  WaterInputs in;
  WiperState low{WiperMode::kLow, 4.0, {}};
  for (int i = 0; i < 30; ++i) wipers.advance(kDt, low);  // up off the bottom edge
  in.blades_before = wipers.poses();
  wipers.advance(kDt, low);
  in.blades_after = wipers.poses();
  const BladePose& b = in.blades_after[0];
  const glm::dvec2 dir(std::cos(b.angle_rad), std::sin(b.angle_rad)), ahead(-dir.y, dir.x);
  const glm::dvec2 centre =
      glm::dvec2(b.pivot_mm) + 400.0 * dir + (0.5 * b.width_mm + 4.0 * r) * ahead;
  // What a conversion leaves: a few particles jittered about each converted drop, overlapping,
  // two of them exactly on top of each other.
  for (int k = 0; k < 3; ++k) {
    const glm::dvec2 at = centre + (40.0 * k) * dir;
    water.add_particle(at, 1.0);
    water.add_particle(at + glm::dvec2(0.4 * r, 0.3 * r) * double(k), 1.0);
    water.add_particle(at + glm::dvec2(-0.5 * r, 0.6 * r), 1.0);
  }
  water.step(kDt, in);
  ASSERT_EQ(water.particles().size(), 9u) << "still particles, inside the moving region";
  double closest = 1e9;
  for (std::size_t i = 0; i < water.particles().size(); ++i) {
    for (std::size_t j = i + 1; j < water.particles().size(); ++j) {
      closest = std::min(closest, glm::length(water.particles()[i].pos - water.particles()[j].pos));
    }
  }
  EXPECT_GE(closest, 2.0 * r * 0.95) << "overlap left after the step (5% tolerance)";
}

// A blade on HIGH turns about 3 degrees in a water step: 21 mm at 400 mm along it. It pushes what
// it reaches as a row of particles pushes: a lone one ends against its edge, three in a strip a
// particle's width apart in the order they stood, and a strip of fifteen, more than the particles'
// region holds, gathered into the four nearest the edge that fit, with all fifteen's water. On the
// edge, all of them (the paper's rule) would lie on one line, a knot the repulsion cannot untie in
// a step.
TEST(WaterTest, ABladeStacksWhatItSweepsInTheOrderItStood) {
  const WindshieldConfig config;
  MeshModel mesh(config, 31);
  ParticleModel particles(config.water);
  BladeSweep sweep(config.water, 31);
  const double r = config.water.particle_radius_mm;
  const double region = config.water.region_particle_diameters * 2.0 * r;  // ahead of the edge
  WaterInputs in = still_inputs();
  BladePose& after = in.blades_after[0];
  after.angle_rad = in.blades_before[0].angle_rad + static_cast<float>(3.0 * M_PI / 180.0);
  const BladePose& before = in.blades_before[0];
  const glm::dvec2 pivot(before.pivot_mm), d0 = blade_direction(before.angle_rad);
  const glm::dvec2 d1 = blade_direction(after.angle_rad);
  const double half = 0.5 * before.width_mm;
  auto place = [&](double along, double gap) {  // gap: between the particle and the blade's edge
    particles.add(pivot + along * d0 + (half + r + gap) * left_normal(d0), 1.0);
  };
  place(200.0, 6.0);  // lone, 6 mm ahead: the blade, 10.5 mm on there, reaches it
  for (int k = 2; k >= 0; --k) place(300.0, 1.0 * k);  // added furthest first
  std::vector<glm::dvec2> fifteen;                     // nearest the edge first
  for (int k = 0; k < 15; ++k) {
    place(400.0, 1.0 * k);
    fifteen.push_back(particles.particles().back().pos);
  }
  place(200.0, 12.0);  // 12 mm ahead where the blade moves 10.5: out of its reach
  const glm::dvec2 unreached = particles.particles().back().pos;
  sweep.sweep(in, mesh, particles);
  const std::vector<ParticleModel::Particle>& p = particles.particles();
  ASSERT_EQ(p.size(), 9u) << "the strip of fifteen gathered into four";
  EXPECT_EQ(p.back().pos, unreached) << "what the blade did not reach stays";
  EXPECT_EQ(p.back().mass, 1.0);
  auto ahead = [&](std::size_t i) { return glm::dot(p[i].pos - pivot, left_normal(d1)) - half; };
  for (std::size_t i = 0; i + 1 < p.size(); ++i) {
    EXPECT_GE(ahead(i), r - 1e-6) << i;
    EXPECT_NEAR(glm::dot(p[i].pos - pivot, d1), i == 0 ? 200.0 : i < 4 ? 300.0 : 400.0, 2.0) << i;
  }
  EXPECT_NEAR(ahead(0), r, 1e-6) << "the lone one against the edge";
  EXPECT_NEAR(ahead(3), r, 1e-6) << "the nearest of three against the edge";
  EXPECT_NEAR(ahead(2), 3.0 * r, 1e-6) << "the next a particle's width ahead";
  EXPECT_NEAR(ahead(1), 5.0 * r, 1e-6) << "and the furthest";
  for (std::size_t i = 0; i < 4; ++i) EXPECT_EQ(p[i].mass, 1.0) << "a strip that fits: " << i;
  double gathered = 0.0;
  for (std::size_t i = 4; i < 8; ++i) {
    EXPECT_NEAR(ahead(i), (2.0 * static_cast<double>(i - 4) + 1.0) * r, 1e-6)
        << "stacked a particle's width apart from the edge: " << i;
    EXPECT_LE(ahead(i), region - r + 1e-6) << "wholly inside the particles' region: " << i;
    EXPECT_NEAR(p[i].mass, 15.0 / 4.0, 1e-12) << "an even share of the strip's water: " << i;
    // The four that stood nearest the edge are kept, each where it stood along the blade (the
    // fifteen stand 0.05 mm apart along it, the blade having turned 3 degrees; the sweep puts each
    // back on the new line to within 2e-5 mm).
    EXPECT_NEAR(glm::dot(p[i].pos - pivot, d1), glm::dot(fifteen[i - 4] - pivot, d1), 1e-3)
        << "the nearest kept, in their order: " << i;
    gathered += p[i].mass;
  }
  EXPECT_NEAR(gathered, 15.0, 1e-12) << "no water lost";
}

// The sweep finds the drops a blade may reach through the grid's cells (MeshModel::drops_within),
// not by a pass over every drop: for convex polygons of every shape and place, the cells it reads
// hold every drop whose centre lies inside, each once, by index, and not many more.
TEST(WaterTest, TheCellsOfAPolygonHoldEveryDropInsideIt) {
  const WindshieldConfig config;
  MeshModel mesh(config, 5);
  RandomStream random(5, 1);
  for (int k = 0; k < 20000; ++k)
    mesh.place({random.uniform(0.0, 1520.0), random.uniform(0.0, 760.0)}, 0.02, nullptr);
  ASSERT_GT(mesh.count(), 10000u);
  std::vector<int> found;
  for (int trial = 0; trial < 200; ++trial) {
    // A convex polygon: a regular one of 3-8 corners, stretched and turned, anywhere (also
    // partly off the glass).
    const int n = 3 + trial % 6;
    const glm::dvec2 centre(random.uniform(-100.0, 1620.0), random.uniform(-100.0, 860.0));
    const double a = random.uniform(2.0, 400.0), b = random.uniform(2.0, 60.0);
    const double turn = random.uniform(0.0, 2.0 * M_PI);
    const glm::dvec2 e(std::cos(turn), std::sin(turn)), f(-e.y, e.x);
    std::vector<glm::dvec2> outline;
    for (int k = 0; k < n; ++k) {
      const double t = (trial % 2 ? 1.0 : -1.0) * 2.0 * M_PI * k / n;
      outline.push_back(centre + a * std::cos(t) * e + b * std::sin(t) * f);
    }
    mesh.drops_within(outline, found);
    ASSERT_TRUE(std::is_sorted(found.begin(), found.end())) << trial;
    ASSERT_TRUE(std::adjacent_find(found.begin(), found.end()) == found.end()) << trial;
    std::size_t inside = 0;
    const std::vector<MeshModel::Drop>& drops = mesh.drops();
    for (std::size_t i = 0; i < drops.size(); ++i) {
      if (!drops[i].alive) continue;
      bool in = true;  // on the inner side of every edge (the corners go round one way)
      for (int k = 0; k < n; ++k) {
        const glm::dvec2 p = outline[k], q = outline[(k + 1) % n], d = drops[i].pos - p;
        const double cross = (q.x - p.x) * d.y - (q.y - p.y) * d.x;
        in &= trial % 2 ? cross >= 0.0 : cross <= 0.0;
      }
      if (!in) continue;
      ++inside;
      ASSERT_TRUE(std::binary_search(found.begin(), found.end(), static_cast<int>(i)))
          << "drop " << i << " inside polygon " << trial;
    }
    for (const int i : found) ASSERT_TRUE(drops[i].alive) << trial;
    // Beside the inside ones, only those of the cells its outline crosses.
    const double perimeter = 4.0 * (a + b);
    EXPECT_LE(found.size(), inside + 2 * static_cast<std::size_t>(perimeter / 2.0) + 4) << trial;
  }
  // A polygon with a corner at no finite place holds every drop.
  const std::vector<glm::dvec2> endless = {
      {100.0, 100.0}, {HUGE_VAL, 100.0}, {100.0, std::nan("")}};
  mesh.drops_within(endless, found);
  EXPECT_EQ(found.size(), mesh.count());
}

// A blade that turns far in a step (a manual wiper can jump) sweeps the drops it passes: the cells
// the sweep reads hold them for a turn of 3, 40 and 85 degrees. (Past a quarter turn the swept
// test, along the blade after the step, no longer covers the sector it crossed.)
TEST(WaterTest, ABladeSweepsTheDropsItPassesHoweverFarItTurns) {
  for (const double turn_deg : {3.0, 40.0, 85.0}) {
    const WindshieldConfig config;
    MeshModel mesh(config, 7);
    ParticleModel particles(config.water);
    BladeSweep sweep(config.water, 7);
    WaterInputs in = still_inputs();
    const BladePose& before = in.blades_before[0];
    in.blades_after[0].angle_rad = before.angle_rad + static_cast<float>(turn_deg * M_PI / 180.0);
    const glm::dvec2 pivot(before.pivot_mm);
    // Drops on rays inside the sector the blade crosses, clear of its ends, on the glass.
    std::vector<glm::dvec2> placed;
    for (int ray = 1; ray < 8; ++ray) {
      const double angle = before.angle_rad + (turn_deg * M_PI / 180.0) * ray / 8.0;
      for (double along = 60.0; along < before.length_mm - 20.0; along += 37.0) {
        const glm::dvec2 p = pivot + along * blade_direction(angle);
        if (config.glass.contains(p)) placed.push_back(p);
      }
    }
    for (const glm::dvec2& p : placed) mesh.place(p, 0.05, nullptr);
    ASSERT_GE(mesh.count(), 10u);
    sweep.sweep(in, mesh, particles);
    for (const glm::dvec2& p : placed)
      EXPECT_LT(mesh.drop_at(p), 0)
          << turn_deg << " degrees, a drop left at " << p.x << ", " << p.y;
  }
}

// The sweep takes exactly the drops that a test of every drop takes (the sweep's own test, over
// the sector's box and the blade's reach), whichever way and however far the blade turns: on
// fields of drops of every size, for turns of either sign up to just under half a circle (where
// the box reaches metres past the glass).
TEST(WaterTest, ABladeSweepsExactlyTheDropsATestOfEveryDropWouldTake) {
  const WindshieldConfig config;
  RandomStream random(11, 2);
  const float turns[] = {0.05f, -0.05f, 0.6f, -0.6f, 1.5f, -1.5f, 3.1415925f, -3.1415925f};
  for (int trial = 0; trial < 48; ++trial) {
    MeshModel mesh(config, 100 + trial);
    ParticleModel particles(config.water);
    BladeSweep sweep(config.water, 100 + trial);
    for (int k = 0; k < 4000; ++k) {
      const glm::dvec2 p(random.uniform(0.0, 1520.0), random.uniform(0.0, 760.0));
      if (config.glass.contains(p)) mesh.place(p, random.uniform(0.001, 20.0), nullptr);
    }
    WaterInputs in = still_inputs();
    const BladePose& before = in.blades_before[0];
    BladePose& after = in.blades_after[0];
    after.angle_rad = before.angle_rad + turns[trial % 8];
    // The test of every drop: the sector's box, grown by the drop's radius, and the blade's reach.
    const double turn = after.angle_rad - before.angle_rad;
    const double side = turn > 0.0 ? 1.0 : -1.0;
    const glm::dvec2 pivot(after.pivot_mm);
    const glm::dvec2 d0 = blade_direction(before.angle_rad), d1 = blade_direction(after.angle_rad);
    const glm::dvec2 n0 = side * left_normal(d0), n1 = side * left_normal(d1);
    const double half = 0.5 * after.width_mm, length = after.length_mm;
    const glm::dvec2 mid = blade_direction(0.5f * (before.angle_rad + after.angle_rad));
    const glm::dvec2 bulge = pivot + mid * (length / std::cos(0.5 * turn));
    const glm::dvec2 tip0 = pivot + d0 * length, tip1 = pivot + d1 * length;
    const glm::dvec2 lo = glm::min(glm::min(pivot, bulge), glm::min(tip0, tip1)) - half;
    const glm::dvec2 hi = glm::max(glm::max(pivot, bulge), glm::max(tip0, tip1)) + half;
    auto taken = [&](const MeshModel::Drop& d) {
      if (d.pos.x < lo.x - d.radius || d.pos.y < lo.y - d.radius || d.pos.x > hi.x + d.radius ||
          d.pos.y > hi.y + d.radius)
        return false;
      const glm::dvec2 rel = d.pos - pivot;
      const double along = glm::dot(d1, rel);
      if (along < 0.0 || along > length) return false;
      return glm::dot(n0, rel) >= -half && glm::dot(n1, rel) < half + d.radius;
    };
    std::vector<bool> expected(mesh.drops().size(), false);
    std::size_t expected_count = 0;
    for (std::size_t i = 0; i < mesh.drops().size(); ++i) {
      expected[i] = mesh.drops()[i].alive && taken(mesh.drops()[i]);
      expected_count += expected[i];
    }
    const std::vector<MeshModel::Drop> drops_before = mesh.drops();
    sweep.sweep(in, mesh, particles);
    for (std::size_t i = 0; i < drops_before.size(); ++i) {
      if (!drops_before[i].alive) continue;
      ASSERT_EQ(!mesh.drops()[i].alive, expected[i])
          << "trial " << trial << " (a turn of " << turns[trial % 8] << " rad), drop " << i
          << " at " << drops_before[i].pos.x << ", " << drops_before[i].pos.y << " radius "
          << drops_before[i].radius;
    }
    if (turns[trial % 8] > 0.5f) {  // (turning down from its park, a blade leaves the glass)
      EXPECT_GT(expected_count, 0u) << trial;
    }
  }
}

// The suspension search reads a flag per cell that the mesh model keeps as its drops grow, move,
// fuse, leave trails that shrink and go: at every step of a run of flowing drops, its answer is
// what a look at every drop gives (a drop at or above the critical radius whose cell lies within
// the search square).
TEST(WaterTest, TheSuspensionSearchSeesWhatATestOfEveryDropWouldSee) {
  const WindshieldConfig config;
  const WaterConfig& w = config.water;
  RandomStream random(23, 2);
  MeshModel mesh(config, 77);
  int near = 0, checked = 0;
  for (int step = 0; step < 240; ++step) {  // 2 s
    for (int k = 0; k < 60; ++k) {          // rain, heavy, some of it in large drops
      const glm::dvec2 p(random.uniform(0.0, 1520.0), random.uniform(0.0, 760.0));
      if (config.glass.contains(p)) mesh.place(p, random.uniform(0.001, 25.0), nullptr);
    }
    mesh.step(kDt, glm::dvec2(0.0, 3.0));
    if (step % 20 != 19) continue;
    for (int k = 0; k < 2000; ++k) {
      const glm::dvec2 p(random.uniform(0.0, 1520.0), random.uniform(0.0, 760.0));
      const int reach = w.suspension_cells / 2;
      const int cu = static_cast<int>(std::floor(p.x / w.cell_mm));
      const int cv = static_cast<int>(std::floor(p.y / w.cell_mm));
      bool expected = false;
      for (const MeshModel::Drop& d : mesh.drops()) {
        if (!d.alive || d.radius < w.critical_radius_mm) continue;
        const int du = static_cast<int>(std::floor(d.pos.x / w.cell_mm)) - cu;
        const int dv = static_cast<int>(std::floor(d.pos.y / w.cell_mm)) - cv;
        if (std::abs(du) <= reach && std::abs(dv) <= reach) expected = true;
      }
      ASSERT_EQ(mesh.holds_critical_drop_near(p), expected)
          << "step " << step << " at " << p.x << ", " << p.y;
      near += expected;
      ++checked;
    }
  }
  EXPECT_GT(near, checked / 20);  // both answers are tested
  EXPECT_LT(near, checked - checked / 20);
}

TEST(WaterTest, AParticlePressedByManyPartsWithoutOvershooting) {
  // One particle with six others each overlapping it by half a diameter, fanned out over its
  // upper right: it gives way by about an overlap, not by the six overlaps summed.
  WaterConfig config;
  ParticleModel model(config);
  const double touch = 2.0 * config.particle_radius_mm;
  const glm::dvec2 pressed(100.0 + 0.1 * touch, 100.0 + 0.1 * touch);
  model.add(pressed, 1.0);
  for (int k = 0; k < 6; ++k) {
    const double a = k * 15.0 * M_PI / 180.0;
    model.add(pressed + 0.5 * touch * glm::dvec2(std::cos(a), std::sin(a)), 1.0);
  }
  model.repel();
  const std::vector<ParticleModel::Particle>& p = model.particles();
  const double moved = glm::length(p[0].pos - pressed);
  EXPECT_GT(moved, 0.2 * touch);
  EXPECT_LT(moved, 0.8 * touch) << "summed, its moves would carry it twice as far";
  for (std::size_t k = 1; k < p.size(); ++k)
    EXPECT_GT(glm::length(p[k].pos - p[0].pos), 0.75 * touch) << k;
}

TEST(WaterTest, SuspensionHoldsParticlesNearALargeDropAndReleasesThemAfter) {
  WaterSim water({}, 17);
  const glm::dvec2 big(700.0, 500.0);
  ASSERT_TRUE(water.add_drop(big, drop_mass_mg(2.8)));  // above critical: it will flow away
  const glm::dvec2 p = big + glm::dvec2(6.0, 0.0);      // 3 cells away: within 7 x 7
  water.add_particle(p, 1.0);
  water.step(kDt, still_inputs());  // parked blades: no region, so only suspension holds it
  ASSERT_EQ(water.particles().size(), 1u) << "suspended next to a large drop";
  for (int i = 0; i < 240 && !water.particles().empty(); ++i) water.step(kDt, still_inputs());
  EXPECT_TRUE(water.particles().empty()) << "released once the drop ran away";
  EXPECT_GE(water.drop_at(p), 0) << "as a mesh drop at its cell";
}

TEST(WaterTest, AParticleAwayFromBladesAndLargeDropsBecomesAMeshDrop) {
  WaterSim water({}, 19);
  water.add_particle({500.0, 500.0}, 1.0);
  water.step(kDt, still_inputs());
  EXPECT_TRUE(water.particles().empty());
  EXPECT_EQ(water.drop_count(), 1u);
  EXPECT_NEAR(water.mass_on_glass(), 1.0, 1e-12);
}

// Small drops every 6 mm over the glass, one wipe at low speed: blade 0's swept sector is left
// nearly dry, the water pushed to the end of the sweep or off the bottom edge.
TEST(WaterTest, ABladeSweepLeavesItsSectorNearlyDry) {
  WaterSim water({}, 23);
  for (double v = 3.0; v < 760.0; v += 6.0) {
    for (double u = 3.0; u < 1520.0; u += 6.0) water.add_drop({u, v}, 0.5);
  }
  const BladeConfig& blade = water.config().wipers.blades[0];
  auto in_sector = [&](glm::dvec2 p) {
    const glm::dvec2 rel = p - blade.pivot_mm;
    const double r = glm::length(rel), a = std::atan2(rel.y, rel.x) * 180.0 / M_PI;
    // Inside the sector, away from its ends where the pushed water collects, and from the band
    // inside the tip's arc: water squeezed along the blade leaves its tip as large drops that run
    // back down into the sector (with them the sector keeps about 17% of its water).
    return r > 150.0 && r < blade.length_mm - 120.0 && a > blade.park_deg + 15.0 &&
           a < blade.park_deg + blade.sweep_deg - 15.0;
  };
  auto sector_mass = [&] {
    double m = 0.0;
    for (const auto& d : water.drops()) {
      if (d.alive && in_sector(d.pos)) m += d.mass;
    }
    for (const auto& p : water.particles()) {
      if (in_sector(p.pos)) m += p.mass;
    }
    return m;
  };
  const double before = sector_mass();
  ASSERT_GT(before, 1000.0);
  WiperMotion wipers(water.config().wipers);
  WiperState single{WiperMode::kSingle, 4.0, {}};
  WaterInputs in;
  std::size_t most_particles = 0;
  for (int i = 0; i < 120 * 2; ++i) {  // one cycle at 45 per minute takes 1.33 s
    in.blades_before = wipers.poses();
    wipers.advance(kDt, single);
    in.blades_after = wipers.poses();
    water.step(kDt, in);
    most_particles = std::max(most_particles, water.particles().size());
    for (const auto& p : water.particles()) {
      // The 0.5 mg drops gather on the blade into whole particles (and a strip deeper than the
      // particles' region into fewer that hold more).
      ASSERT_GE(p.mass, water.particle_mass() * (1.0 - 1e-12)) << "step " << i;
    }
  }
  EXPECT_GT(most_particles, 100u);
  ASSERT_TRUE(wipers.parked());
  const double after = sector_mass();
  EXPECT_LT(after, 0.05 * before) << "before " << before << " mg, after " << after << " mg";
  EXPECT_GT(water.ledger().wiped_off, 0.0);
  EXPECT_NEAR(ledger_total(water), water.ledger().arrived, 1e-6);
}

// In = on the glass + wiped off + drained + evaporated, through rain, fusion, trails, both
// conversions and wiping: the standard heavy-rain drive for 6 s.
TEST(WaterTest, MassIsConservedInTheHeavyRainDrive) {
  const Scenario scenario = highway_heavy_rain();
  Simulation simulation(scenario.seed, scenario.at(0.0));
  for (int i = 0; i < 6 * 30; ++i) {
    simulation.apply(scenario.at((i + 1) / 30.0));
    simulation.advance(1.0 / 30.0);
  }
  const WaterSim& water = simulation.water();
  const WaterLedger& l = water.ledger();
  EXPECT_GT(l.arrived, 10000.0);
  EXPECT_GT(l.wiped_off, 0.0);
  EXPECT_GT(l.evaporated, 0.0);
  EXPECT_NEAR(ledger_total(water), l.arrived, 1e-9 * l.arrived);
  const WindshieldState& w = simulation.state().windshield;
  EXPECT_EQ(w.drops, water.drop_count());
  EXPECT_GT(w.metaballs.size(), w.drops);
  EXPECT_GT(w.glass_wet_fraction, 0.0);
  EXPECT_LT(w.glass_wet_fraction, 1.0);
}

TEST(WaterTest, SameSeedSameWaterOtherSeedOtherWater) {
  const Scenario scenario = highway_heavy_rain();
  auto run = [&](std::uint64_t seed) {
    Simulation simulation(seed, scenario.at(0.0));
    for (int i = 0; i < 30; ++i) {
      simulation.apply(scenario.at((i + 1) / 30.0));
      simulation.advance(1.0 / 30.0);
    }
    return simulation.state().windshield.metaballs;
  };
  auto same = [](const std::vector<Metaball>& a, const std::vector<Metaball>& b) {
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i) {
      if (a[i].u_mm != b[i].u_mm || a[i].v_mm != b[i].v_mm || a[i].radius_mm != b[i].radius_mm)
        return false;
    }
    return true;
  };
  const auto first = run(7), again = run(7), other = run(8);
  ASSERT_FALSE(first.empty());
  EXPECT_TRUE(same(first, again));
  EXPECT_FALSE(same(first, other));
}

}  // namespace
}  // namespace downpour::sim
