// The windshield's own cost (issue 3): the water simulation's step per frame in the standard
// heavy-rain drive, and its load (drops, particles, metaballs, wet glass), as JSON. Reports,
// never fails on a slow machine.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "server/sim/scenario.hpp"
#include "server/sim/simulation.hpp"

namespace {

using namespace downpour;
using Clock = std::chrono::steady_clock;

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Downpour windshield benchmark: water simulation cost per frame, as JSON"};
  double seconds = 20.0;
  double fps = 30.0;
  bool trace = false;
  std::string scene = "highway_heavy_rain";
  app.add_option("--scene", scene)->check(CLI::IsMember({"highway_heavy_rain", "city_drizzle"}));
  app.add_option("--seconds", seconds, "simulated seconds of the highway_heavy_rain drive");
  app.add_option("--fps", fps);
  app.add_flag("--trace", trace, "print the load every simulated second on stderr");
  CLI11_PARSE(app, argc, argv);

  const sim::Scenario scenario =
      scene == "city_drizzle" ? sim::city_drizzle() : sim::highway_heavy_rain();
  sim::Simulation simulation(scenario.seed, scenario.at(0.0));
  std::vector<double> step_ms;
  std::vector<double> metaballs, drops, particles, wet;
  const double dt = 1.0 / fps;
  const int frames = static_cast<int>(seconds * fps);
  for (int i = 0; i < frames; ++i) {
    simulation.apply(scenario.at((i + 1) * dt));
    const auto t0 = Clock::now();
    simulation.advance(dt);
    step_ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
    const sim::WindshieldState& w = simulation.state().windshield;
    if (i >= frames / 4) {  // past the first wipes: a steady state
      metaballs.push_back(static_cast<double>(w.metaballs.size()));
      drops.push_back(w.drops);
      particles.push_back(w.particles);
      wet.push_back(w.glass_wet_fraction);
    }
    if (trace && (i + 1) % static_cast<int>(fps) == 0) {
      const sim::WaterLedger& l = simulation.water().ledger();
      std::fprintf(stderr,
                   "t=%5.1f s  step %.2f ms  drops %u  particles %u  metaballs %zu  wet %.3f  "
                   "arrived %.0f on %.0f wiped %.0f drained %.0f evaporated %.0f mg\n",
                   simulation.state().sim_time_s, step_ms.back(), w.drops, w.particles,
                   w.metaballs.size(), w.glass_wet_fraction, l.arrived,
                   simulation.water().mass_on_glass(), l.wiped_off, l.drained, l.evaporated);
    }
  }
  nlohmann::json out;
  out["scene"] = scenario.name;
  out["simulated_s"] = seconds;
  out["frame_dt_s"] = dt;
  out["sim_step_ms_median"] = median(step_ms);
  out["sim_step_ms_p90"] = [&] {
    std::vector<double> v = step_ms;
    std::sort(v.begin(), v.end());
    return v[v.size() * 9 / 10];
  }();
  out["metaballs_median"] = median(metaballs);
  out["drops_median"] = median(drops);
  out["particles_median"] = median(particles);
  out["glass_wet_fraction_median"] = median(wet);
  std::printf("%s\n", out.dump(2).c_str());
  return 0;
}
