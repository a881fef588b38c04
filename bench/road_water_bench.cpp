// The water on the road (road_water.hpp) over the timeline, without GL: 1, 5 and 15 minutes
// of rain on a car standing on the test track, then 5 minutes after the rain stops, and a minute
// driving at 30 m/s; prints JSON lines (the paved cells' states, puddle cells, the ledger, the
// step's cost at 30 steps a second) and, with --out, writes a picture of the window at each point.
//   downpour-road-water-bench [--out DIR] [--rain MM_H] [--seed N] [--s METRES]
// In a picture the car's window is seen from above, +x right and +y up, 4 pixels a cell: the
// ground grey by its relief (darker lower), the verge green, wet cells darker, standing water
// blue (a film pale, a puddle deep blue by its depth).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "bench/stats.hpp"
#include "server/sim/road_water.hpp"
#include "tests/support/png_io.hpp"

using namespace downpour;

namespace {

constexpr int kScale = 4;

void picture(const sim::RoadWater& water, const sim::RoadSurface& surface,
             const std::string& path) {
  const int n = water.cells();
  testing::RgbaImage image{n * kScale, n * kScale, {}};
  image.pixels.assign(static_cast<std::size_t>(image.width) * image.height * 4, 255);
  const sim::Track& track = surface.track();
  const double cell = water.config().cell_m;
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const std::size_t c = static_cast<std::size_t>(j) * n + i;
      double rgb[3];
      if (!water.paved()[c]) {
        rgb[0] = 0.35, rgb[1] = 0.5, rgb[2] = 0.3;
      } else {
        const glm::dvec2 xy = (glm::dvec2(water.origin() + glm::ivec2(i, j)) + 0.5) * cell;
        const sim::Track::Projection p = track.project(xy, 40.0);
        const double relief = surface.relief(p.s, p.lateral);  // <= 0
        const double grey = 0.75 + std::max(relief, -0.03) * 12.0;
        rgb[0] = rgb[1] = rgb[2] = grey;
        const double w = water.water()[c];
        switch (water.state_of(w)) {
          case sim::RoadState::kDry:
            break;
          case sim::RoadState::kWet:
            for (double& v : rgb) v *= 0.7;
            break;
          case sim::RoadState::kDrench:
            rgb[0] *= 0.55, rgb[1] *= 0.65, rgb[2] = std::min(1.0, rgb[2] * 0.9);
            break;
          case sim::RoadState::kPuddle: {
            const double depth = std::min((w - water.config().capacity_m) / 0.01, 1.0);
            rgb[0] = 0.1 * (1.0 - depth), rgb[1] = 0.3 * (1.0 - depth) + 0.1, rgb[2] = 0.9;
            break;
          }
        }
      }
      for (int y = 0; y < kScale; ++y) {
        for (int x = 0; x < kScale; ++x) {
          // Rows top-down: +y up.
          const int row = (n - 1 - j) * kScale + y, col = i * kScale + x;
          std::uint8_t* px = &image.pixels[(static_cast<std::size_t>(row) * image.width + col) * 4];
          for (int k = 0; k < 3; ++k)
            px[k] = static_cast<std::uint8_t>(std::clamp(rgb[k], 0.0, 1.0) * 255.0);
        }
      }
    }
  }
  testing::write_png(path, image);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Downpour road water benchmark: the water model over a timeline, as JSON lines"};
  std::string out;
  double rain = 30.0, s0 = 150.0;
  std::uint64_t seed = 7;
  app.add_option("--out", out, "a folder for the pictures");
  app.add_option("--rain", rain, "mm/h")->check(CLI::Range(0.0, 200.0));
  app.add_option("--seed", seed);
  app.add_option("--s", s0, "where the car stands along the track (m)");
  CLI11_PARSE(app, argc, argv);

  const sim::Track track = sim::Track::test_track();
  const sim::RoadSurface surface(track, seed);
  sim::RoadWater water(surface);
  auto at = [&](double s) {
    const sim::TrackFrame f = track.at(s);
    return glm::dvec2(f.position) + f.left * track.lane_centre(0);
  };
  const double dt = 1.0 / 30.0;
  std::vector<double> ms;
  double t = 0.0, s = s0;
  auto run = [&](double until_s, double rate, double speed) {
    for (; t < until_s - 1e-9; t += dt) {
      s += speed * dt;
      const auto t0 = std::chrono::steady_clock::now();
      water.step(at(s), rate, dt);
      ms.push_back(
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    }
  };
  auto report = [&](const char* name, double speed) {
    int counts[4] = {0, 0, 0, 0}, paved = 0;
    for (std::size_t c = 0; c < water.water().size(); ++c) {
      if (!water.paved()[c]) continue;
      ++paved;
      ++counts[static_cast<int>(water.state_of(water.water()[c]))];
    }
    const sim::RoadWater::Ledger& l = water.ledger();
    const double closure =
        l.rain_in_m3 > 0.0
            ? (water.stored_m3() + l.drained_m3 + l.evaporated_m3 + l.thrown_m3 - l.rain_in_m3) /
                  l.rain_in_m3
            : 0.0;
    std::printf(
        "{\"at\": \"%s\", \"time_s\": %.0f, \"speed_mps\": %.0f, \"dry\": %.3f, \"wet\": %.3f, "
        "\"drench\": %.3f, \"puddle\": %.3f, \"puddle_cells\": %d, \"rain_in_m3\": %.4f, "
        "\"stored_m3\": %.4f, \"drained_m3\": %.4f, \"evaporated_m3\": %.6f, "
        "\"ledger_closure\": %.2e, \"step_ms\": %.3f, \"step_ms_p90\": %.3f}\n",
        name, t, speed, counts[0] / double(paved), counts[1] / double(paved),
        counts[2] / double(paved), counts[3] / double(paved), counts[3], l.rain_in_m3,
        water.stored_m3(), l.drained_m3, l.evaporated_m3, closure, bench::median(ms),
        bench::percentile(ms, 0.9));
    ms.clear();
    if (!out.empty()) picture(water, surface, out + "/" + name + ".png");
  };
  run(60.0, rain, 0.0);
  report("rain_1min", 0.0);
  run(300.0, rain, 0.0);
  report("rain_5min", 0.0);
  run(900.0, rain, 0.0);
  report("rain_15min", 0.0);
  run(1200.0, 0.0, 0.0);
  report("dry_5min", 0.0);
  run(1260.0, rain, 30.0);
  report("rain_driving_1min", 30.0);
  return 0;
}
