// Fuzz target: the simulation under a feed a client could send. The input is a sequence of
// (length, DriveRequest bytes) records; each request the service would accept is applied and the
// simulation advanced by its dt_s as the server steps it, with the step's helper thread (capped at
// 0.2 s per input, with a small rain box and road, so that one input stays quick). After every step
// the state must be finite and the water must be accounted for: what arrived on the glass is on it,
// wiped off, drained or evaporated; the rain in the air stays bounded and finite; the road's water
// is finite and its ledger closes.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <string>

#include <fuzzer/FuzzedDataProvider.h>

#include "downpour/v1/downpour.pb.h"
#include "server/rpc/validation.hpp"
#include "server/sim/simulation.hpp"
#include "server/sim/worker_thread.hpp"

namespace {

using namespace downpour;

void require(bool ok) {
  if (!ok) std::abort();
}

void check(const sim::Simulation& simulation) {
  const sim::SceneState& s = simulation.state();
  require(std::isfinite(s.sim_time_s));
  require(std::isfinite(s.vehicle.position_m.x) && std::isfinite(s.vehicle.position_m.y));
  const sim::WaterSim& water = simulation.water();
  const sim::WaterLedger l = water.ledger();
  const double on_glass = water.mass_on_glass();
  require(std::isfinite(on_glass) && on_glass >= 0.0);
  const double accounted = on_glass + l.wiped_off + l.drained + l.evaporated;
  require(std::abs(accounted - l.arrived) <= 1e-6 * std::max(1.0, l.arrived));
  // The rain in the air: bounded, finite, of the sizes the field draws.
  const sim::RainField& rain = simulation.rain();
  require(rain.drops().size() <= sim::kMaxRainDrops);
  for (const sim::RainDrop& d : rain.drops()) {
    require(std::isfinite(d.position_m.x) && std::isfinite(d.position_m.y) &&
            std::isfinite(d.position_m.z));
    require(d.diameter_mm >= rain.config().smallest_drawn_mm &&
            d.diameter_mm <= rain.config().max_diameter_mm);
  }
  // Its splashes as published: bounded, finite, young.
  const sim::RainState& published = simulation.state().rain;
  require(published.splashes.size() <= sim::kMaxRainSplashes);
  for (const sim::SplashState& s : published.splashes) {
    require(std::isfinite(s.position.x) && std::isfinite(s.position.y) &&
            std::isfinite(s.position.z));
    require(s.age_s >= 0.0f && s.age_s <= sim::kSplashLifeS + 1e-6);
    require(s.diameter_mm >= rain.config().smallest_drawn_mm - 1e-6 &&
            s.diameter_mm <= rain.config().max_diameter_mm + 1e-6);
  }
  // The water on the road: finite, and every cubic metre accounted for.
  const sim::RoadWater& road = simulation.road();
  const sim::RoadWater::Ledger& rl = road.ledger();
  const double stored = road.stored_m3();
  require(std::isfinite(stored) && stored >= -1e-9);
  require(std::abs(stored + rl.drained_m3 + rl.evaporated_m3 + rl.thrown_m3 - rl.rain_in_m3) <=
          1e-9 * std::max(1.0, rl.rain_in_m3));
  for (const sim::TireWater& t : simulation.state().tires)
    require(std::isfinite(t.water_mm) && t.water_mm >= -1e-9 && t.standing_mm >= 0.0);
  for (const auto& d : water.drops()) {
    if (!d.alive) continue;
    require(std::isfinite(d.pos.x) && std::isfinite(d.pos.y) && std::isfinite(d.mass));
    require(d.mass > 0.0);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzedDataProvider in(data, size);
  const rpc::Limits limits;
  const std::uint8_t seed = in.ConsumeIntegral<std::uint8_t>();
  // A fresh simulation for each seed is built once and copied for each input: the copy is the
  // same state as a new one, at a small part of the cost (the glass mesh).
  static std::array<std::unique_ptr<sim::Simulation>, 256> fresh;
  if (!fresh[seed]) {
    sim::Update initial;
    initial.weather = sim::Weather{};
    initial.weather->rain_rate_mm_h = 20.0;
    sim::SimulationConfig config;
    // A smaller rain box (the same code, a twentieth of the drops).
    config.rain.length_m = 6.0;
    config.rain.width_m = 4.0;
    config.rain.height_m = 3.0;
    // And smaller road rings: each input's first road step fills them (16,384 cells at the
    // default size held the fuzzer to about 20 inputs a second). Two rings, so that water still
    // crosses a ring's border and moves between rings.
    config.road.cells = 48;
    config.road.levels = 2;
    fresh[seed] = std::make_unique<sim::Simulation>(seed, initial, config);
  }
  sim::Simulation simulation = *fresh[seed];
  static sim::WorkerThread helper("dp-world");
  double budget_s = 0.2;  // simulated time per input: 48 sub-steps, a wiper stroke's start
  while (in.remaining_bytes() > 0 && budget_s > 0.0) {
    const std::string bytes = in.ConsumeRandomLengthString(512);
    v1::DriveRequest req;
    if (!req.ParseFromString(bytes)) continue;
    sim::Update update;
    if (!rpc::to_update(req.update(), "update", limits, &update).ok()) continue;
    if (!rpc::check_dt(req.dt_s(), "dt_s", true, limits).ok()) continue;
    simulation.apply(update);
    const double dt = std::min(req.dt_s(), std::min(0.1, budget_s));
    budget_s -= std::max(dt, 0.01);
    if (dt > 0.0) simulation.advance(dt, &helper);
    check(simulation);
  }
  return 0;
}
