// The water's surface as the light meets it (glass_water_surface.hpp): the shapes of sessile drops
// (a cap's height from its contact angle, the flat top of a wide body, a rivulet's width from its
// water), the grid that lists every body wherever its outline reaches, and the shapes the
// simulation publishes (tears downhill, running drops with a tail, trails as cylinders holding
// their water).
#include "server/sim/glass_water_surface.hpp"

#include <atomic>
#include <cmath>
#include <set>
#include <thread>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include "server/sim/drop_physics.hpp"
#include "server/sim/random.hpp"
#include "server/sim/water.hpp"
#include "server/sim/worker_thread.hpp"

namespace downpour::sim {
namespace {

constexpr double kDeg = M_PI / 180.0;

// rho^2 at p for a body, as its fields define its outline (glass_water_surface.hpp).
double rho2(const WaterBody& b, glm::dvec2 p) {
  const glm::dvec2 d = p - glm::dvec2(b.u_mm, b.v_mm);
  double x = d.x * b.axis_u + d.y * b.axis_v;
  const double y = -d.x * b.axis_v + d.y * b.axis_u;
  x -= std::clamp(x, -static_cast<double>(b.half_length_mm), static_cast<double>(b.half_length_mm));
  const double ax = x >= 0.0 ? b.front_mm : b.back_mm;
  return (x / ax) * (x / ax) + (y / b.side_mm) * (y / b.side_mm);
}

bool listed(const GlassWaterSurface& s, std::size_t body, glm::dvec2 p) {
  const int i = static_cast<int>(std::floor(p.x / GlassWaterSurface::kCellMm));
  const int j = static_cast<int>(std::floor(p.y / GlassWaterSurface::kCellMm));
  if (i < 0 || j < 0 || i >= s.cells_u || j >= s.cells_v) return false;
  const std::uint32_t cell = s.cells[static_cast<std::size_t>(j) * s.cells_u + i];
  const std::uint32_t first = cell >> GlassWaterSurface::kCountBits;
  const std::uint32_t count = cell & ((1u << GlassWaterSurface::kCountBits) - 1);
  for (std::uint32_t k = first; k < first + count; ++k) {
    if (s.entries[k] == body) return true;
  }
  return false;
}

TEST(GlassWaterSurfaceTest, ACapRisesToItsContactAnglesHeight) {
  // A spherical cap of contact radius a meeting the glass at q: R = a / sin q, height a tan(q/2),
  // as the body's fields give it: a (sqrt(1 / sin^2) - cot) at its centre.
  for (const double q : {40.0, 70.0, 90.0}) {
    const WaterBody b = cap_body({100.0f, 100.0f}, 1.5f, q, false);
    const double height = 1.5 * (std::sqrt(b.inv_sin2) - b.cot);
    const double expected = q < 87.0 ? 1.5 * std::tan(0.5 * q * kDeg) : 1.5 * std::tan(43.5 * kDeg);
    EXPECT_NEAR(height, expected, 1e-5) << q;
    EXPECT_EQ(b.top_mm, 0.0f);
  }
  // A wide body's flat top: 2 l_c sin(q / 2), 1.85 mm for water at 40 degrees.
  EXPECT_NEAR(puddle_thickness_mm(40.0), 1.847, 1e-3);
  EXPECT_NEAR(cap_body({0.0f, 0.0f}, 6.0f, 40.0).top_mm, 1.847f, 1e-3f);
}

TEST(GlassWaterSurfaceTest, ARivuletHoldsItsWater) {
  // A cylinder's cross-section is a circular segment of area w^2 (q - sin q cos q) / sin^2 q.
  const double w = cylinder_half_width_mm(0.9, 6.0, 40.0);
  const double q = 40.0 * kDeg;
  const double area = w * w * (q - std::sin(q) * std::cos(q)) / (std::sin(q) * std::sin(q));
  EXPECT_NEAR(area * 6.0, 0.9, 1e-9);
  EXPECT_GT(w, 0.4);  // a thread of water about a millimetre wide
  EXPECT_LT(w, 0.7);
}

TEST(GlassWaterSurfaceTest, EveryPointOfABodyIsListedInItsCell) {
  const GlassConfig glass;
  GlassWaterSurface surface;
  RandomStream random(3, 0);
  for (int k = 0; k < 400; ++k) {
    const glm::vec2 at(static_cast<float>(random.uniform(20.0, 1500.0)),
                       static_cast<float>(random.uniform(20.0, 740.0)));
    WaterBody b = k % 3 == 2
                      ? cylinder_body(at, glm::normalize(glm::vec2(0.3f, -1.0f)), 0.5f, 3.0f, 40.0)
                      : cap_body(at, static_cast<float>(random.uniform(0.3, 6.0)), 40.0);
    if (k % 3 == 1) {  // a tear or a running drop
      b.axis_u = 0.6f, b.axis_v = -0.8f;
      b.front_mm *= 1.2f, b.back_mm *= 1.6f, b.side_mm *= 0.85f;
    }
    surface.bodies.push_back(b);
  }
  surface.index(glass);
  int inside = 0;
  for (std::size_t k = 0; k < surface.bodies.size(); ++k) {
    const WaterBody& b = surface.bodies[k];
    const double reach = body_reach_mm(b);
    for (int n = 0; n < 200; ++n) {
      const glm::dvec2 p = glm::dvec2(b.u_mm, b.v_mm) +
                           glm::dvec2(random.uniform(-reach, reach), random.uniform(-reach, reach));
      if (rho2(b, p) >= 1.0 || p.x < 0.0 || p.y < 0.0) continue;
      ++inside;
      ASSERT_TRUE(listed(surface, k, p)) << "body " << k << " at (" << p.x << ", " << p.y << ")";
    }
  }
  EXPECT_GT(inside, 20000);
  // And a cell lists only bodies that come near it: far from all of them, none. A drop as wide as
  // a cell, at a cell's centre, reaches the 3 x 3 cells round it.
  const float c = static_cast<float>(GlassWaterSurface::kCellMm);
  GlassWaterSurface one;
  one.bodies.push_back(cap_body({50.5f * c, 50.5f * c}, c, 40.0));
  one.index(glass);
  EXPECT_TRUE(listed(one, 0, {50.5 * c, 50.5 * c}));
  EXPECT_FALSE(listed(one, 0, {53.0 * c, 50.5 * c}));
  EXPECT_EQ(one.entries.size(), 9u);
  // A drop of 1 mm radius inside a cell is listed there alone; across a corner, in its 4 cells.
  GlassWaterSurface small;
  small.bodies.push_back(cap_body({50.5f * c, 50.5f * c}, 1.0f, 40.0));
  small.bodies.push_back(cap_body({60.0f * c, 60.0f * c}, 1.0f, 40.0));
  small.index(glass);
  EXPECT_EQ(small.entries.size(), 5u);
}

// The step's helper lists half of the bodies (Simulation::advance): the lists, their order and
// the wet fraction are those of one thread listing them all. A busy helper is not waited for.
TEST(GlassWaterSurfaceTest, AHelperListsHalfOfTheBodiesAndTheResultIsTheSame) {
  const GlassConfig glass;
  RandomStream random(11, 0);
  GlassWaterSurface alone;
  for (std::size_t k = 0; k < 3 * GlassWaterSurface::kShareFrom; ++k) {  // a helper shares them
    const glm::vec2 at(static_cast<float>(random.uniform(0.0, 1500.0)),
                       static_cast<float>(random.uniform(0.0, 760.0)));
    WaterBody b = cap_body(at, static_cast<float>(random.uniform(0.3, 9.0)), 40.0);
    if (k % 4 == 1) b = cylinder_body(at, glm::normalize(glm::vec2(0.3f, -1.0f)), 0.5f, 3.0f, 40.0);
    alone.bodies.push_back(b);
  }
  GlassWaterSurface helped = alone, busy = alone;
  alone.index(glass);
  WorkerThread helper("dp-test");
  helped.index(glass, &helper);
  EXPECT_EQ(helped.cells, alone.cells);
  EXPECT_EQ(helped.entries, alone.entries);
  EXPECT_EQ(helped.wet_fraction, alone.wet_fraction);
  EXPECT_GT(alone.wet_fraction, 0.1);
  std::atomic<bool> release{false};
  helper.start([&release] {
    while (!release.load()) std::this_thread::yield();
  });
  busy.index(glass, &helper);  // lists every body itself
  release = true;
  helper.wait();
  EXPECT_EQ(busy.cells, alone.cells);
  EXPECT_EQ(busy.entries, alone.entries);
  EXPECT_EQ(busy.wet_fraction, alone.wet_fraction);
}

TEST(GlassWaterSurfaceTest, TheWetCellsAreThoseWhoseCentreLiesUnderWater) {
  // Bodies of every kind, most a few cells wide (index()'s path for small bodies), some wider (its
  // general path), one in ten at the grid's edges and corners; none with a cell's centre within a
  // hair of its outline or of the glass's, so that rounding cannot decide. The wet cells are
  // counted from the centres within the glass's outline.
  const GlassConfig glass;
  const double cell = GlassWaterSurface::kCellMm;
  const auto c = [&](double i) { return static_cast<float>((i + 0.5) * cell); };
  GlassWaterSurface one;  // wets one cell: how many cells the glass has
  one.bodies.push_back(cap_body({c(100), c(50)}, 1.0f, 40.0));
  one.index(glass);
  ASSERT_GT(one.wet_fraction, 0.0);
  const double glass_cells = 1.0 / one.wet_fraction;
  // How far inside the glass's outline a point lies (< 0: outside).
  const auto inside = [&](double u, double v) {
    const double inset = glass.inset_mm(v);
    return std::min({glass.height_mm - v, u - inset, glass.bottom_width_mm - inset - u});
  };
  RandomStream random(5, 0);
  GlassWaterSurface surface;
  std::set<std::pair<int, int>> wet;
  while (surface.bodies.size() < 3000) {
    const int kind = static_cast<int>(surface.bodies.size() % 5);
    glm::dvec2 at(random.uniform(20.0, 1500.0), random.uniform(20.0, 740.0));
    if (surface.bodies.size() % 10 == 0) {  // within 8 mm of an edge of the grid
      const double grid_w = 1520.0, grid_h = 191 * cell;
      at = random.uniform() < 0.5
               ? glm::dvec2(random.uniform(0.0, grid_w), random.uniform() < 0.5
                                                             ? random.uniform(-2.0, 8.0)
                                                             : grid_h - random.uniform(-2.0, 8.0))
               : glm::dvec2(random.uniform() < 0.5 ? random.uniform(-2.0, 8.0)
                                                   : grid_w - random.uniform(-2.0, 8.0),
                            random.uniform(0.0, grid_h));
    }
    const glm::vec2 centre(at);
    const float r =
        static_cast<float>(kind == 4 ? random.uniform(3.0, 9.0) : random.uniform(0.3, 2.6));
    const glm::vec2 axis =
        glm::normalize(glm::vec2(static_cast<float>(random.uniform(-1.0, 1.0)), -1.0f));
    WaterBody b = kind == 3 ? cylinder_body(centre, axis, 0.6f * r, 0.5f * r, 40.0)
                            : cap_body(centre, r, 40.0);
    if (kind == 1 || kind == 2) {  // a tear, or a drop running along its heading with a tail
      b.axis_u = axis.x, b.axis_v = axis.y;
      b.front_mm *= kind == 1 ? 1.2f : 1.0f;
      b.back_mm *= kind == 1 ? 0.85f : 1.6f;
      b.side_mm *= kind == 1 ? 1.0f : 0.85f;
    }
    std::vector<std::pair<int, int>> centres;
    bool clear = true;
    const int reach = static_cast<int>(body_reach_mm(b) / cell) + 2;
    const int i0 = static_cast<int>(b.u_mm / cell), j0 = static_cast<int>(b.v_mm / cell);
    for (int j = std::max(j0 - reach, 0); j <= j0 + reach; ++j) {
      for (int i = std::max(i0 - reach, 0); i <= i0 + reach; ++i) {
        const double q = rho2(b, {c(i), c(j)}), in_glass = inside(c(i), c(j));
        if (std::abs(q - 1.0) < 1e-3 || (q < 1.0 && std::abs(in_glass) < 1e-3)) clear = false;
        if (q < 1.0 && in_glass > 0.0) centres.emplace_back(i, j);
      }
    }
    if (!clear) continue;
    surface.bodies.push_back(b);
    wet.insert(centres.begin(), centres.end());
  }
  surface.index(glass);
  EXPECT_GT(wet.size(), 3000u);
  EXPECT_EQ(std::lround(surface.wet_fraction * glass_cells), static_cast<long>(wet.size()));
}

TEST(GlassWaterSurfaceTest, WhereTheWaterIsAndHowMuchOfTheGlassItWets) {
  const GlassConfig glass;
  GlassWaterSurface surface;
  surface.bodies.push_back(cap_body({400.0f, 300.0f}, 2.0f, 40.0));
  surface.bodies.push_back(cap_body({400.0f, 301.0f}, 1.0f, 40.0));  // lower, inside the first
  surface.bodies.push_back(cap_body({800.0f, 400.0f}, 10.0f, 40.0));
  surface.bodies.push_back(cap_body({200.0f, 500.0f}, 20.0f, 40.0));
  surface.index(glass);
  // The highest body's cap over a point: r (1 - rho^2); none off the water.
  EXPECT_FLOAT_EQ(surface.top_height({400.0f, 300.0f}), 2.0f);
  EXPECT_FLOAT_EQ(surface.top_height({401.0f, 300.0f}), 1.5f);
  EXPECT_EQ(surface.top_height({404.0f, 300.0f}), 0.0f);
  EXPECT_EQ(surface.top_height({-5.0f, 300.0f}), 0.0f);
  // Their area over the trapezoid's, sampled every 4 mm.
  const double area = M_PI * (4.0 + 100.0 + 400.0);
  const double glass_area = 0.5 * (glass.bottom_width_mm + glass.top_width_mm) * glass.height_mm;
  EXPECT_NEAR(surface.wet_fraction, area / glass_area, 0.1 * area / glass_area);
}

TEST(GlassWaterSurfaceTest, TheSimulationPublishesDropsTearsRunsAndTrails) {
  WindshieldConfig config;
  WaterSim water(config, 11);
  // A small drop, one wider than the capillary length, and one big enough to run down the glass.
  water.add_drop({300.0, 400.0}, drop_mass_mg(0.8));
  water.add_drop({700.0, 400.0}, drop_mass_mg(2.1));
  water.add_drop({1100.0, 600.0}, drop_mass_mg(4.0));
  WaterInputs in;
  for (int b = 0; b < 2; ++b) {
    const BladeConfig& c = config.wipers.blades[b];
    in.blades_before[b] =
        in.blades_after[b] = {glm::vec2(c.pivot_mm), static_cast<float>(c.park_deg * kDeg),
                              static_cast<float>(c.length_mm), static_cast<float>(c.width_mm)};
  }
  for (int i = 0; i < 60; ++i) water.step(1.0 / 60.0, in);
  WindshieldState state;
  water.publish(state);
  ASSERT_TRUE(state.surface);
  const GlassWaterSurface& s = *state.surface;
  int tears = 0, runs = 0, trails = 0, drops = 0;
  for (const WaterBody& b : s.bodies) {
    if (b.half_length_mm > 0.0f) {
      ++trails;
      EXPECT_EQ(b.side_mm, b.front_mm) << "a cylinder: round across";
      continue;
    }
    ++drops;
    if (b.back_mm > b.front_mm) ++runs;           // a tail behind its run
    if (b.front_mm > 1.05f * b.back_mm) ++tears;  // heavier downhill
  }
  EXPECT_EQ(drops, static_cast<int>(water.drop_count()) - trails);
  EXPECT_GE(runs, 1) << "the big drop runs with a tail";
  EXPECT_GE(tears, 1) << "the wide resting drop sags downhill";
  EXPECT_GE(trails, 1) << "the running drop leaves a rivulet";
  // Every body listed where it is.
  for (std::size_t k = 0; k < s.bodies.size(); ++k)
    EXPECT_TRUE(listed(s, k, {s.bodies[k].u_mm, s.bodies[k].v_mm}));
}

}  // namespace
}  // namespace downpour::sim
