// Renders the views of a standard scene at a given time to PNG files, to look at what the
// renderer draws. Usage: downpour-render-views OUT_DIR [highway_heavy_rain|city_drizzle] [t_s]
//   [width height] [rain_rate_mm_h]
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "server/render/renderer.hpp"
#include "server/sim/scenario.hpp"
#include "server/sim/simulation.hpp"
#include "tests/support/png_io.hpp"

int main(int argc, char** argv) {
  using namespace downpour;
  if (argc < 2) {
    std::fprintf(stderr,
                 "usage: downpour-render-views OUT_DIR [scene] [t_s] [width height] [rain_mm_h]\n");
    return 2;
  }
  const std::string out = argv[1];
  const std::string scene_name = argc > 2 ? argv[2] : "highway_heavy_rain";
  const double t = argc > 3 ? std::atof(argv[3]) : 10.0;
  const int width = argc > 5 ? std::atoi(argv[4]) : 640;
  const int height = argc > 5 ? std::atoi(argv[5]) : 360;
  const sim::Scenario scenario =
      scene_name == "city_drizzle" ? sim::city_drizzle() : sim::highway_heavy_rain();
  sim::Update update = scenario.at(t);
  if (argc > 6 && update.weather) update.weather->rain_rate_mm_h = std::atof(argv[6]);

  const auto t0 = std::chrono::steady_clock::now();
  auto renderer = render::Renderer::create({});
  const auto t1 = std::chrono::steady_clock::now();
  std::printf("renderer %s, created in %.0f ms\n", renderer->gl_renderer().c_str(),
              std::chrono::duration<double, std::milli>(t1 - t0).count());
  renderer->set_profiling(true);
  sim::Simulation simulation(scenario.seed, update);
  simulation.advance(t);
  for (sim::View view :
       {sim::View::kCockpit, sim::View::kRoad, sim::View::kWindshield, sim::View::kRain}) {
    sim::ViewSpec spec{view, width, height, 85, 0.0, std::nullopt};
    render::render_image(*renderer, spec,
                         simulation.state());  // the first draw compiles shader variants
    testing::RgbaImage image{width, height,
                             render::render_image(*renderer, spec, simulation.state())};
    std::string path = out + "/" + std::string(sim::view_name(view)) + ".png";
    testing::write_png(path, image);
    std::printf("%s:", path.c_str());
    for (const auto& pass : renderer->last_pass_timings())
      std::printf(" %s %.2f ms", pass.name.c_str(), pass.ms);
    std::printf("\n");
  }
  return 0;
}
