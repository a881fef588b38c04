// The windshield's own cost (issue 3), as JSON: the water simulation's step per frame in a
// standard drive and its load (drops, particles, metaballs, wet glass); then the COCKPIT view's
// render cost, each pass and the whole frame wet and dry, at each --size, for two windshields:
// a hand-made one of about --metaballs metaballs (the paper's load: 3000) and the one the drive
// left. Reports, never fails on a slow machine.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "bench/view_costs.hpp"
#include "server/sim/scenario.hpp"
#include "server/sim/simulation.hpp"
#include "tests/render/windshield_fixture.hpp"

namespace {

using namespace downpour;
using Clock = std::chrono::steady_clock;

using bench::median;

nlohmann::json render_costs(const sim::SceneState& scene, const std::vector<std::string>& sizes,
                            int frames) {
  std::vector<bench::NamedView> views;
  for (const std::string& size : sizes) {
    const auto x = size.find('x');
    const int width = std::stoi(size.substr(0, x)), height = std::stoi(size.substr(x + 1));
    views.push_back({"COCKPIT", sim::view_spec(sim::View::kCockpit, width, height)});
  }
  nlohmann::json out = nlohmann::json::array();
  for (const bench::ViewCost& c : bench::measure_views(views, scene, frames)) {
    nlohmann::json passes = nlohmann::json::object();
    for (const auto& [name, ms] : c.passes) passes[name] = ms;
    out.push_back({{"view", c.name},
                   {"width", c.width},
                   {"height", c.height},
                   {"frame_ms_wet", c.wet_ms},
                   {"frame_ms_dry", c.dry_ms},
                   {"frame_cpu_ms_wet", c.wet_cpu_ms},
                   {"frame_cpu_ms_dry", c.dry_cpu_ms},
                   {"windshield_passes_ms", c.windshield_passes_ms()},
                   {"passes_ms", passes}});
  }
  return out;
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
  std::vector<std::string> sizes{"640x360", "1280x720"};
  int render_frames = 30;
  int hand_made_metaballs = 3000;
  app.add_option("--size", sizes, "COCKPIT sizes to render, WIDTHxHEIGHT")
      ->check([](const std::string& s) {
        const auto x = s.find('x');
        const bool ok = x != std::string::npos && x > 0 && x + 1 < s.size() &&
                        s.find_first_not_of("0123456789x") == std::string::npos &&
                        std::stoi(s.substr(0, x)) <= 4096 && std::stoi(s.substr(x + 1)) <= 4096;
        return ok ? std::string() : "expected WIDTHxHEIGHT, e.g. 640x360";
      });
  app.add_option("--render-frames", render_frames, "frames per measurement; 0: no rendering")
      ->check(CLI::Range(0, 10000));
  app.add_option("--metaballs", hand_made_metaballs, "the hand-made windshield's load")
      ->check(CLI::Range(0, 100000));
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
  if (render_frames > 0) {
    const sim::SceneState& simulated = simulation.state();
    sim::SceneState hand_made_scene = simulated;
    hand_made_scene.windshield =
        testing::rainy_windshield(hand_made_scene.glass, hand_made_metaballs);
    const sim::SceneState& hand_made = hand_made_scene;
    out["render"] = nlohmann::json::array();
    for (const auto& [name, scene] :
         {std::pair("hand_made", &hand_made), std::pair("simulated", &simulated)}) {
      out["render"].push_back({{"windshield", name},
                               {"metaballs", scene->windshield.metaballs.size()},
                               {"views", render_costs(*scene, sizes, render_frames)}});
    }
  }
  std::printf("%s\n", out.dump(2).c_str());
  return 0;
}
