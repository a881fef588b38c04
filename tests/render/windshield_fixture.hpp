// Hand-made windshield water for the render tests and the render-views tool: deterministic states
// built without the simulation (drops, trails, wiped sectors, water piled at the blades), and the
// water's surface that the simulation would publish with them.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <numbers>
#include <tuple>
#include <utility>

#include "server/sim/glass_water_surface.hpp"
#include "server/sim/random.hpp"
#include "server/sim/scenario.hpp"
#include "server/sim/simulation.hpp"
#include "server/sim/windshield.hpp"

namespace downpour::testing {

// The render tests' scene: the highway 10 s in, on the straight, heavy rain; the windshield as the
// simulation left it (replace it for tests about the water), or dry glass without simulating the
// water (for tests of other effects: ten seconds of heavy rain on the glass take a while).
// Simulated once per weather and kept.
inline sim::SceneState highway_scene(double rain_mm_h = 25.0, double cloudiness = 0.95,
                                     bool water = true) {
  static std::map<std::tuple<double, double, bool>, sim::SceneState> simulated;
  const std::tuple key(rain_mm_h, cloudiness, water);
  const auto it = simulated.find(key);
  if (it != simulated.end()) return it->second;
  const sim::Scenario scenario = sim::highway_heavy_rain();
  sim::Update update = scenario.at(10.0);
  update.weather->rain_rate_mm_h = rain_mm_h;
  update.weather->cloudiness = cloudiness;
  sim::SimulationConfig config;
  config.simulate_water = water;
  sim::Simulation simulation(scenario.seed, update, config);
  simulation.advance(10.0);
  return simulated.emplace(key, simulation.state()).first->second;
}

// The highway's car parked (at its place 10 s into the drive) with the wipers off, `seconds` of
// rain at `rain_mm_h` on the glass, the sun `sun_altitude_deg` high under `cloudiness`; at night
// (the sun well below the horizon) the street lights and the car's own lamps are on. The rain in
// the air is left out: these scenes measure the glass. Simulated once per set of inputs and kept.
inline sim::SceneState parked_in_rain(double rain_mm_h, double seconds, double sun_altitude_deg,
                                      double cloudiness) {
  static std::map<std::tuple<double, double, double, double>, sim::SceneState> simulated;
  const std::tuple key(rain_mm_h, seconds, sun_altitude_deg, cloudiness);
  const auto it = simulated.find(key);
  if (it != simulated.end()) return it->second;
  const sim::Scenario scenario = sim::highway_heavy_rain();
  sim::Update update = scenario.at(10.0);
  update.vehicle->velocity_mps = glm::dvec3(0.0);
  update.wipers = sim::WiperState{};  // off
  update.weather->rain_rate_mm_h = rain_mm_h;
  update.weather->sun_altitude_deg = sun_altitude_deg;
  update.weather->cloudiness = cloudiness;
  update.traffic = std::vector<sim::TrafficVehicle>{};
  sim::Simulation simulation(scenario.seed, update);
  simulation.advance(seconds);
  sim::SceneState scene = simulation.state();
  scene.rain.drops.clear();
  scene.rain.splashes.clear();
  scene.spray.reset();
  return simulated.emplace(key, scene).first->second;
}

// A blade of the default wipers (sim::WiperConfig) at an angle from +u, degrees.
inline sim::BladePose blade_at(int index, double angle_deg) {
  const sim::BladeConfig c = sim::WiperConfig{}.blades[index];
  sim::BladePose b;
  b.pivot_mm = glm::vec2(c.pivot_mm);
  b.angle_rad = static_cast<float>(angle_deg * std::numbers::pi / 180.0);
  b.length_mm = static_cast<float>(c.length_mm);
  b.width_mm = static_cast<float>(c.width_mm);
  return b;
}

inline std::array<sim::BladePose, 2> parked_blades() {
  const sim::WiperConfig w;
  return {blade_at(0, w.blades[0].park_deg), blade_at(1, w.blades[1].park_deg)};
}

// The surface of the metaballs' water (a round cap each) and the share of the glass it wets.
inline void build_surface(sim::WindshieldState& state, const sim::GlassConfig& glass) {
  state.surface = sim::surface_from_metaballs(state.metaballs, glass);
  state.glass_wet_fraction = state.surface->wet_fraction;
}

// Rain on the glass with the wipers part-way up their sweep: drops of many sizes (a main metaball,
// some with sub-metaballs that make the outline irregular), a few running drops with trails above
// them, the blades' swept sectors clear but for fresh small drops, and water piled along the
// blades' leading edges (particles). About `metaballs` metaballs in all.
inline sim::WindshieldState rainy_windshield(const sim::GlassConfig& glass, int metaballs,
                                             std::array<double, 2> blade_deg = {40.0, 36.0},
                                             std::uint64_t seed = 7) {
  sim::RandomStream rng(seed, 0);  // the simulation's own generator
  sim::WindshieldState s;
  const sim::WiperConfig wipers;
  for (int i = 0; i < 2; ++i) s.blades[i] = blade_at(i, blade_deg[i]);
  const auto add = [&](double u, double v, double r) {
    if (glass.contains({u, v}))
      s.metaballs.push_back({static_cast<float>(u), static_cast<float>(v), static_cast<float>(r)});
  };
  // In a blade's swept sector (from park up to its angle now).
  const auto wiped = [&](double u, double v) {
    for (int i = 0; i < 2; ++i) {
      const sim::BladeConfig& c = wipers.blades[i];
      const double du = u - c.pivot_mm.x, dv = v - c.pivot_mm.y;
      const double angle = std::atan2(dv, du) * 180.0 / std::numbers::pi;
      if (std::hypot(du, dv) < c.length_mm && angle > c.park_deg - 2.0 && angle < blade_deg[i])
        return true;
    }
    return false;
  };
  // Water pushed by each blade: particles in rows along its leading (upper) edge.
  const int particle_budget = metaballs / 6;
  const double particle_r = sim::WaterConfig{}.particle_radius_mm;
  for (int i = 0; i < 2; ++i) {
    const sim::BladePose& b = s.blades[i];
    const glm::dvec2 dir(std::cos(b.angle_rad), std::sin(b.angle_rad));
    const glm::dvec2 side(-dir.y, dir.x);
    for (int k = 0; k < particle_budget / 2; ++k) {
      const double along = rng.uniform(0.15, 1.0) * b.length_mm;
      const double across =
          0.5 * b.width_mm + particle_r * (1.0 + 2.0 * std::floor(rng.uniform(0, 3)));
      const glm::dvec2 p = glm::dvec2(b.pivot_mm) + along * dir + across * side;
      add(p.x, p.y, particle_r);
    }
  }
  const std::size_t particles = s.metaballs.size();
  // Running drops with trails of small drops above them.
  for (int k = 0; k < 12; ++k) {
    const double u = rng.uniform(60.0, glass.bottom_width_mm - 60.0);
    const double v = rng.uniform(80.0, glass.height_mm - 150.0);
    if (wiped(u, v)) continue;
    const double r = rng.uniform(2.3, 3.2);
    add(u, v, r);
    add(u + 0.6 * r, v + 0.3 * r, 0.6 * r);
    double tu = u;
    for (double tv = v + r; tv < v + rng.uniform(40.0, 140.0); tv += 1.6) {
      tu += rng.uniform(-0.5, 0.5);
      add(tu, tv, rng.uniform(0.5, 0.9));
    }
  }
  // Drops: mostly small, a few large; in the swept sectors only fresh small ones.
  while (static_cast<int>(s.metaballs.size()) < metaballs) {
    const double u = rng.uniform(0.0, glass.bottom_width_mm);
    const double v = rng.uniform(0.0, glass.height_mm);
    const double size = rng.uniform();
    double r = 0.5 + 1.4 * size * size * size + rng.uniform(0.0, 0.3);
    if (wiped(u, v)) {
      if (rng.uniform() > 0.15) continue;
      r = std::min(r, 0.8);
    }
    add(u, v, r);
    if (r > 1.0 && rng.uniform() < 0.6) {
      const int subs = 1 + static_cast<int>(rng.uniform(0.0, 3.0));
      for (int j = 0; j < subs; ++j) {
        const double a = rng.uniform(0.0, 2.0 * std::numbers::pi);
        const double d = rng.uniform(0.5, 0.9) * r;
        add(u + d * std::cos(a), v + d * std::sin(a), rng.uniform(0.4, 0.6) * r);
      }
    }
  }
  s.metaballs.resize(std::min<std::size_t>(s.metaballs.size(), metaballs));
  s.particles = static_cast<std::uint32_t>(std::min(particles, s.metaballs.size()));
  s.drops = static_cast<std::uint32_t>(s.metaballs.size()) - s.particles;
  build_surface(s, glass);
  return s;
}

// A splash: a patch of water about `radius_mm` across, made of a ring of metaballs around one.
inline void add_splash(sim::WindshieldState& state, double u, double v, double radius_mm) {
  const float r = static_cast<float>(0.45 * radius_mm);
  state.metaballs.push_back({static_cast<float>(u), static_cast<float>(v), r});
  for (int k = 0; k < 6; ++k) {
    const double a = k * std::numbers::pi / 3.0 + 0.3;
    state.metaballs.push_back({static_cast<float>(u + 0.55 * radius_mm * std::cos(a)),
                               static_cast<float>(v + 0.55 * radius_mm * std::sin(a)),
                               static_cast<float>(r * (0.8 + 0.05 * k))});
  }
}

// The golden images' windshield: rain of about 1500 metaballs with the blades part-way up, a few
// large splashes (to be seen at 256 x 144) and a row of single drops of growing size.
inline sim::WindshieldState golden_windshield(const sim::GlassConfig& glass) {
  sim::WindshieldState s = rainy_windshield(glass, 1500, {55.0, 48.0}, 11);
  add_splash(s, 420.0, 560.0, 40.0);
  add_splash(s, 1150.0, 620.0, 28.0);
  add_splash(s, 760.0, 690.0, 22.0);
  for (int k = 0; k < 6; ++k) {
    s.metaballs.push_back({static_cast<float>(200.0 + 130.0 * k), 300.0f, 1.0f + 1.2f * k});
  }
  build_surface(s, glass);
  return s;
}

}  // namespace downpour::testing
