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

// The rings' water over the coarsest window, a pixel per finest cell (the finest cell that holds
// each place), +y up.
void picture(const sim::RoadWater& water, const sim::RoadSurface& surface,
             const std::string& path) {
  const int levels = water.levels();
  const double cell = water.cell_m(0);
  const int side = water.cells() << (levels - 1);
  const glm::dvec2 corner = glm::dvec2(water.origin(levels - 1)) * water.cell_m(levels - 1);
  testing::RgbaImage image{side, side, {}};
  image.pixels.assign(static_cast<std::size_t>(side) * side * 4, 255);
  const sim::Track& track = sim::Track::built_in();  // the surface's (main() below)
  double s_guess = track.project(corner + 0.5 * side * cell, 40.0).s;
  for (int j = 0; j < side; ++j) {
    for (int i = 0; i < side; ++i) {
      const glm::dvec2 xy = corner + (glm::dvec2(i, j) + 0.5) * cell;
      const sim::Track::Projection p = track.project_near(xy, s_guess);
      if (i == 0) s_guess = p.s;
      double rgb[3];
      // (Paved as the cell holding it is: a coarse cell is road or not as its centre is.)
      const int c = water.cell_at(xy);
      if (c < 0 || !water.paved()[c]) {
        rgb[0] = 0.35, rgb[1] = 0.5, rgb[2] = 0.3;
      } else {
        const double relief = surface.relief(p.s, p.lateral);  // <= 0
        const double grey = 0.75 + std::max(relief, -0.03) * 12.0;
        rgb[0] = rgb[1] = rgb[2] = grey;
        const double w = water.water_m(xy);
        switch (water.cell_state(static_cast<std::size_t>(c))) {
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
      std::uint8_t* px =
          &image.pixels[(static_cast<std::size_t>(side - 1 - j) * image.width + i) * 4];
      for (int k = 0; k < 3; ++k)
        px[k] = static_cast<std::uint8_t>(std::clamp(rgb[k], 0.0, 1.0) * 255.0);
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

  const sim::Track& track = sim::Track::built_in();
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
    // The paved area in each state (m^2), of the finest ring's cells in puddles.
    double counts[4] = {0.0, 0.0, 0.0, 0.0}, paved = 0.0;
    int puddle_cells = 0;
    const std::size_t per_level = static_cast<std::size_t>(water.cells()) * water.cells();
    for (std::size_t c = 0; c < water.water().size(); ++c) {
      if (!water.paved()[c] || !water.owned()[c]) continue;
      const double size = water.cell_m(static_cast<int>(c / per_level));
      const sim::RoadState state = water.cell_state(c);
      paved += size * size;
      counts[static_cast<int>(state)] += size * size;
      puddle_cells += c < per_level && state == sim::RoadState::kPuddle;
    }
    const sim::RoadWater::Ledger& l = water.ledger();
    const double closure = l.rain_in_m3 > 0.0
                               ? (water.stored_m3() + l.drained_m3 + l.evaporated_m3 + l.thrown_m3 -
                                  l.returned_m3 - l.rain_in_m3) /
                                     l.rain_in_m3
                               : 0.0;
    std::printf(
        "{\"at\": \"%s\", \"time_s\": %.0f, \"speed_mps\": %.0f, \"dry\": %.3f, \"wet\": %.3f, "
        "\"drench\": %.3f, \"puddle\": %.3f, \"puddle_cells\": %d, \"rain_in_m3\": %.4f, "
        "\"stored_m3\": %.4f, \"drained_m3\": %.4f, \"evaporated_m3\": %.6f, "
        "\"ledger_closure\": %.2e, \"step_ms\": %.3f, \"step_ms_p90\": %.3f}\n",
        name, t, speed, counts[0] / paved, counts[1] / paved, counts[2] / paved, counts[3] / paved,
        puddle_cells, l.rain_in_m3, water.stored_m3(), l.drained_m3, l.evaporated_m3, closure,
        bench::median(ms), bench::percentile(ms, 0.9));
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
