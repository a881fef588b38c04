// The spray's benchmark (README, Frame budget), as JSON: a drive at 25 m/s behind trucks, with
// cars in the next lane, on a road that starts with puddles everywhere (4 mm: the most spray, and
// splashes whose sheets are the liquid body), until the spray holds its budget of parcels; then
// the scene at that moment rendered --frames times per view at 640 x 360 with each smoothing in
// turn in one renderer (seed 001: plane fitting 9 x 9 x 3, the bilateral filter 7 x 7 x 22, none):
// - the spray's passes (the layer and its composite), each finished (profiling on), medians;
// - the smoothing's share: each method's spray pass less the pass without smoothing;
// - the spray's share of whole frames (no finish between passes, as the server renders): the
//   frame with the spray less the frame without, frame by frame, median;
// - the simulation's spray step while driving (median per step), and its parcels for the renderer
//   (the image, classified body or spray; median and p90 per step).
// Usage: downpour-spray-bench [--frames N] [--seconds S] [--road-mm MM] [--cpu-splat|--gpu-splat]
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "bench/stats.hpp"
#include "server/render/renderer.hpp"
#include "tests/support/spray_drive.hpp"

using json = nlohmann::json;
using namespace downpour;

namespace {

// The drive: the ego car behind two trucks, three cars in the next lane ahead, every one at
// 25 m/s.
sim::Simulation drive(double seconds, double road_mm, std::vector<double>& spray_step_ms,
                      std::vector<double>& spray_image_ms) {
  testing::SprayDrive d;
  d.seconds = seconds;
  d.truck_gap_m = 22.0;
  d.road_water_m = road_mm * 1e-3;
  d.rain_mm_h = 10.0;
  d.extra_traffic = {{2, 8.0, 1, {4.5, 1.8, 1.5}},
                     {3, 40.0, 1, {4.5, 1.8, 1.5}},
                     {4, 60.0, 0, testing::kTruckSize},
                     {5, 75.0, 1, {4.5, 1.8, 1.5}}};
  return testing::drive(d, [&](const sim::Simulation& s) {
    spray_step_ms.push_back(s.last_advance_timing().spray_ms);
    spray_image_ms.push_back(s.last_advance_timing().spray_image_ms);
  });
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"The spray's benchmark: its passes at 640x360 with each smoothing, as JSON"};
  int frames = 20;
  double seconds = 5.0;
  double road_mm = 4.0;
  bool cpu = false, gpu = false;
  app.add_option("--frames", frames, "frames measured per view and smoothing")
      ->check(CLI::Range(1, 1000));
  app.add_option("--seconds", seconds, "the drive before the scene is taken")
      ->check(CLI::Range(0.5, 60.0));
  app.add_option("--road-mm", road_mm, "the road's water at the start")
      ->check(CLI::Range(0.0, 20.0));
  app.add_flag("--cpu-splat", cpu, "the CPU draws the parcels (llvmpipe's default)");
  app.add_flag("--gpu-splat", gpu, "the GPU draws the parcels (a GPU's default)");
  CLI11_PARSE(app, argc, argv);

  std::vector<double> step_ms, image_ms;
  const sim::Simulation simulation = drive(seconds, road_mm, step_ms, image_ms);
  const sim::SceneState wet = simulation.state();
  sim::SceneState dry = wet;
  dry.spray.reset();
  json out;
  out["parcels"] = simulation.spray().particles().size();
  out["max_parcels"] = simulation.spray().config().max_particles;
  out["spray_step_ms"] = bench::median(step_ms);
  out["spray_step_p90_ms"] = bench::percentile(step_ms, 0.9);
  // The parcels for the renderer, classified body or spray (in the step thread's publish).
  out["spray_image_ms"] = bench::median(image_ms);
  out["spray_image_p90_ms"] = bench::percentile(image_ms, 0.9);
  const auto& counts = wet.spray->counts;
  out["parcels_by_kind"] = {
      {"mist", counts[0]}, {"small", counts[1]}, {"medium", counts[2]}, {"large", counts[3]}};

  auto renderer = render::Renderer::create({});
  if (cpu || gpu) renderer->set_spray_cpu_splat(cpu);
  out["renderer"] = renderer->gl_renderer();
  out["cpu_splat"] = renderer->spray_cpu_splat();
  auto session = renderer->open_session();
  std::vector<std::uint8_t> pixels;
  constexpr int kWarmUp = 2;
  for (const sim::View view : {sim::View::kCockpit, sim::View::kRoad}) {
    const sim::ViewSpec spec = sim::view_spec(view, 640, 360);
    json row = {{"view", std::string(sim::view_name(view))}, {"size", "640x360"}};
    // Each frame drawn with each smoothing in turn, so that a machine whose speed drifts affects
    // them alike.
    const std::vector<render::SpraySmoothing> methods = {render::SpraySmoothing::kPlaneFit,
                                                         render::SpraySmoothing::kBilateral,
                                                         render::SpraySmoothing::kNone};
    std::map<std::string, std::map<std::string, std::vector<double>>> passes;
    renderer->set_profiling(true);
    for (int i = 0; i < frames + kWarmUp; ++i) {
      for (const render::SpraySmoothing smoothing : methods) {
        renderer->set_spray_smoothing(smoothing);
        renderer->finish(renderer->render(*session, 0, spec, wet), pixels);
        if (i < kWarmUp) continue;
        for (const auto& p : renderer->last_pass_timings())
          passes[render::spray_smoothing_name(smoothing)][p.name].push_back(p.ms);
      }
    }
    const auto drawn = renderer->last_spray_drawn();
    row["drawn"] = {{"body", drawn[0]}, {"spray", drawn[1]}, {"haze", drawn[2]}};
    std::map<std::string, double> spray_ms;
    for (const render::SpraySmoothing smoothing : methods) {
      const std::string name = render::spray_smoothing_name(smoothing);
      // The layer: every pass of the spray's chain but the composite.
      double layer = 0.0;
      json chain = json::object();
      for (auto& [pass, ms] : passes[name]) {
        if (pass.rfind("spray_", 0) != 0) continue;
        chain[pass] = bench::median(ms);
        if (pass != "spray_composite") layer += bench::median(ms);
      }
      const double composite = bench::median(passes[name]["spray_composite"]);
      spray_ms[name] = layer;
      row[name] = {{"spray_ms", layer},
                   {"spray_composite_ms", composite},
                   {"total_ms", layer + composite},
                   {"passes_ms", chain}};
    }
    const double plane = spray_ms["plane_fit"] - spray_ms["none"];
    const double bilateral = spray_ms["bilateral"] - spray_ms["none"];
    row["smoothing_ms"] = {{"plane_fit", plane}, {"bilateral", bilateral}};
    row["bilateral_over_plane_fit"] = plane > 0.0 ? json(bilateral / plane) : json(nullptr);
    const double total = row["plane_fit"]["total_ms"].get<double>();
    row["parcels_per_ms"] =
        total > 0.0 ? json(out["parcels"].get<double>() / total) : json(nullptr);

    // The spray's share of whole frames, plane fitting, no finish between passes.
    renderer->set_spray_smoothing(render::SpraySmoothing::kPlaneFit);
    renderer->set_profiling(false);
    const bench::Added added = bench::added_to_frames(
        frames, kWarmUp,
        [&] { renderer->finish(renderer->render(*session, 0, spec, wet), pixels); },
        [&] { renderer->finish(renderer->render(*session, 0, spec, dry), pixels); });
    row["spray_in_frame_ms"] = added.added_ms;
    row["ceiling_ms"] = 6.0;
    out["views"].push_back(row);
    std::fprintf(stderr, "%s done\n", std::string(sim::view_name(view)).c_str());
  }
  std::printf("%s\n", out.dump(2).c_str());
  return 0;
}
