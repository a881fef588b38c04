// Renders the views of a standard scene at a given time to PNG files, to look at what the
// renderer draws. Usage:
//   downpour-render-views OUT_DIR [highway_heavy_rain|city_drizzle] [t_s] [width height]
//     [rain_rate_mm_h] [--windshield N] [--blades A B] [--dash] [--measure FRAMES] [--wipe]
//     [--speed MPS]
// --speed MPS: the car's speed along its heading (0: standing), in place of the scene's.
// --road-water FILM_MM: a hand-made road (tests/render/road_water_fixture.hpp): a film of FILM_MM
//   over the paved width (0: dry), and with --puddles the render tests' puddles ahead of the car.
// --spray-drive GAP_M ROAD_MM SECONDS: in place of the scene's drive, a drive along the track
//   (tests/support/spray_drive.hpp) at --speed (25 m/s if not given) for SECONDS behind a truck
//   GAP_M ahead (0: alone), on a road that starts with ROAD_MM of water everywhere, in the scene's
//   rain (or rain_mm_h).
// --windshield N: a hand-made rainy windshield (tests/render/windshield_fixture.hpp) of about N
//   metaballs instead of the simulation's, with the wiper blades at A and B degrees from +u
//   (--blades; default 40 36); N = 0: the render tests' golden windshield. --dash: also the COCKPIT
//   view from the forward (dash) camera.
// --measure FRAMES: median costs over FRAMES frames of each COCKPIT, ROAD and WINDSHIELD view:
// whole
//   frames with profiling off, wall and CPU time of all threads (and the same frame with a dry
//   windshield, no blades), then each
//   pass with profiling on, in a renderer of its own (a glFinish mid-frame slows llvmpipe).
// --sun ALT AZ: the sun's altitude and azimuth (degrees) in place of the scene's; --cloud C its
//   cloudiness [0, 1]; --fog F its fog density [0, 1]; --no-relief: without the relief's shadows
//   (seed 002).
// --xodr FILE ROAD S LANE: on the roads of an OpenDRIVE file, the car on road ROAD (its id) at S
//   metres along it, in lane LANE (an OpenDRIVE lane id: negative to the right of the reference
//   line, driving along it; positive against it), without the scene's traffic; --lift M PITCH: the
//   car M metres over its place, pitched PITCH degrees nose down (to look at the roads from above).
// --road-whole: the chase view's road drawn whole, not its near part at half size (the default on
//   llvmpipe: RendererOptions::road_at_half).
// --wipe: a wipe as a picture sequence: the scene's weather and drive at t_s with the wipers off
//   for t_s seconds, then one SINGLE wipe; COCKPIT, WINDSHIELD (and --dash) written before it,
//   every sixth of the cycle through it, and after (wipe_K_*.png).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <glm/gtc/constants.hpp>
#include <glm/trigonometric.hpp>

#include "bench/view_costs.hpp"
#include "server/render/cpu/camera.hpp"
#include "server/render/cpu/view_wet_fraction.hpp"
#include "server/render/renderer.hpp"
#include "server/sim/opendrive_roads.hpp"
#include "server/sim/scenario.hpp"
#include "server/sim/simulation.hpp"
#include "tests/render/road_water_fixture.hpp"
#include "tests/render/windshield_fixture.hpp"
#include "tests/support/png_io.hpp"
#include "tests/support/spray_drive.hpp"

namespace {

// The renderer's options (--road-whole).
downpour::render::RendererOptions g_options;

using namespace downpour;

using bench::NamedView;

void measure(const std::vector<NamedView>& views, const sim::SceneState& wet, int frames) {
  for (const bench::ViewCost& c : bench::measure_views(views, wet, frames)) {
    std::printf("%s %dx%d frame (profiling off): wet %.2f ms (CPU %.2f), dry %.2f ms (CPU %.2f)\n",
                c.name.c_str(), c.width, c.height, c.wet_ms, c.wet_cpu_ms, c.dry_ms, c.dry_cpu_ms);
    std::printf("%s %dx%d passes (profiling on, median ms):", c.name.c_str(), c.width, c.height);
    for (const auto& [name, ms] : c.passes) std::printf(" %s %.2f", name.c_str(), ms);
    std::printf("; windshield passes %.2f\n", c.windshield_passes_ms());
  }
}

// The wipers off for dry_s, then one wipe (SINGLE) in the same weather and drive, 30 frames a
// second; pictures before the wipe, at every sixth of its cycle and after it.
int wipe_sequence(const std::string& out, std::uint64_t seed, sim::Update update, double dry_s,
                  int width, int height, bool dash) {
  update.wipers = sim::WiperState{sim::WiperMode::kOff, 4.0, {}};
  sim::Simulation simulation(seed, update);
  simulation.advance(dry_s);
  update.wipers = sim::WiperState{sim::WiperMode::kSingle, 4.0, {}};
  simulation.apply(update);
  const double cycle_s = 60.0 / sim::WiperConfig{}.low_cycles_per_min;
  std::vector<NamedView> views{
      {"COCKPIT", sim::view_spec(sim::View::kCockpit, width, height)},
      {"WINDSHIELD", sim::view_spec(sim::View::kWindshield, width, height)}};
  if (dash) {
    views.push_back({"COCKPIT_dash", sim::view_spec(sim::View::kCockpit, width, height,
                                                    render::dash_camera_pose())});
  }
  auto renderer = render::Renderer::create(g_options);
  const int frames_per_picture = static_cast<int>(std::lround(cycle_s / 6.0 * 30.0));
  for (int k = 0; k <= 7; ++k) {
    const sim::SceneState& scene = simulation.state();
    for (const NamedView& v : views) {
      render::render_image(*renderer, v.spec, scene);
      testing::RgbaImage image{width, height, render::render_image(*renderer, v.spec, scene)};
      const std::string path = out + "/wipe_" + std::to_string(k) + "_" + v.name + ".png";
      testing::write_png(path, image);
    }
    std::printf(
        "wipe_%d: t %.2f s, blades %.1f %.1f deg, %zu metaballs, glass wet %.3f, "
        "view wet %.3f\n",
        k, scene.sim_time_s - dry_s, glm::degrees(scene.windshield.blades[0].angle_rad),
        glm::degrees(scene.windshield.blades[1].angle_rad), scene.windshield.metaballs.size(),
        scene.windshield.glass_wet_fraction, render::view_wet_fraction(views[0].spec, scene));
    for (int f = 0; f < frames_per_picture; ++f) simulation.advance(1.0 / 30.0);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> positional;
  int windshield_metaballs = -1;
  std::array<double, 2> blades{40.0, 36.0};
  bool dash = false;
  int measure_frames = 0;
  bool wipe = false;
  double speed = -1.0;
  double road_film_mm = -1.0;
  double dry_after_s = -1.0;
  bool puddles = false;
  std::optional<testing::SprayDrive> spray_drive;
  std::optional<std::array<double, 2>> sun;
  double cloud = -1.0, fog = -1.0;
  bool relief = true;
  std::shared_ptr<const sim::OpenDriveRoads> roads;
  std::string xodr_road;
  double xodr_s = 0.0;
  int xodr_lane = -1;
  double lift_m = 0.0, lift_pitch_deg = 0.0;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--xodr" && i + 4 < argc) {
      std::ifstream file(argv[i + 1], std::ios::binary);
      std::stringstream text;
      text << file.rdbuf();
      roads = std::make_shared<const sim::OpenDriveRoads>(road::parse_opendrive(text.str()));
      xodr_road = argv[i + 2];
      xodr_s = std::atof(argv[i + 3]);
      xodr_lane = std::atoi(argv[i + 4]);
      i += 4;
      continue;
    }
    if (arg == "--lift" && i + 2 < argc) {
      lift_m = std::atof(argv[i + 1]);
      lift_pitch_deg = std::atof(argv[i + 2]);
      i += 2;
      continue;
    }
    if (arg == "--windshield" && i + 1 < argc) {
      windshield_metaballs = std::atoi(argv[++i]);
    } else if (arg == "--blades" && i + 2 < argc) {
      blades = {std::atof(argv[i + 1]), std::atof(argv[i + 2])};
      i += 2;
    } else if (arg == "--dash") {
      dash = true;
    } else if (arg == "--wipe") {
      wipe = true;
    } else if (arg == "--road-water" && i + 1 < argc) {
      road_film_mm = std::atof(argv[++i]);
    } else if (arg == "--dry-after" && i + 1 < argc) {
      dry_after_s = std::atof(argv[++i]);
    } else if (arg == "--spray-drive" && i + 3 < argc) {
      spray_drive.emplace();
      const double gap = std::atof(argv[i + 1]);
      if (gap > 0.0) spray_drive->truck_gap_m = gap;
      spray_drive->road_water_m = std::atof(argv[i + 2]) * 1e-3;
      spray_drive->seconds = std::atof(argv[i + 3]);
      i += 3;
    } else if (arg == "--sun" && i + 2 < argc) {
      sun = {std::atof(argv[i + 1]), std::atof(argv[i + 2])};
      i += 2;
    } else if (arg == "--cloud" && i + 1 < argc) {
      cloud = std::atof(argv[++i]);
    } else if (arg == "--fog" && i + 1 < argc) {
      fog = std::atof(argv[++i]);
    } else if (arg == "--no-relief") {
      relief = false;
    } else if (arg == "--road-whole") {
      g_options.road_at_half = false;
    } else if (arg == "--puddles") {
      puddles = true;
    } else if (arg == "--speed" && i + 1 < argc) {
      speed = std::atof(argv[++i]);
    } else if (arg == "--measure" && i + 1 < argc) {
      measure_frames = std::atoi(argv[++i]);
    } else {
      positional.push_back(arg);
    }
  }
  if (positional.empty()) {
    std::fprintf(stderr,
                 "usage: downpour-render-views OUT_DIR [scene] [t_s] [width height] [rain_mm_h]"
                 " [--windshield N] [--blades A B] [--dash] [--measure FRAMES] [--wipe]"
                 " [--speed MPS] [--road-water FILM_MM [--puddles]] [--dry-after S]"
                 " [--spray-drive GAP_M ROAD_MM SECONDS] [--sun ALT AZ] [--cloud C] [--fog F]"
                 " [--no-relief] [--road-whole]\n");
    return 2;
  }
  const std::string out = positional[0];
  const std::string scene_name = positional.size() > 1 ? positional[1] : "highway_heavy_rain";
  const double t = positional.size() > 2 ? std::atof(positional[2].c_str()) : 10.0;
  const int width = positional.size() > 4 ? std::atoi(positional[3].c_str()) : 640;
  const int height = positional.size() > 4 ? std::atoi(positional[4].c_str()) : 360;
  const sim::Scenario scenario =
      scene_name == "city_drizzle" ? sim::city_drizzle() : sim::highway_heavy_rain();
  sim::Update update = scenario.at(t);
  if (positional.size() > 5 && update.weather)
    update.weather->rain_rate_mm_h = std::atof(positional[5].c_str());
  if (sun && update.weather) {
    update.weather->sun_altitude_deg = (*sun)[0];
    update.weather->sun_azimuth_deg = (*sun)[1];
  }
  if (cloud >= 0.0 && update.weather) update.weather->cloudiness = cloud;
  if (fog >= 0.0 && update.weather) update.weather->fog_density = fog;
  if (speed >= 0.0 && update.vehicle) {
    const double yaw = glm::radians(update.vehicle->rotation.yaw_deg);
    update.vehicle->velocity_mps = glm::dvec3(std::cos(yaw), std::sin(yaw), 0.0) * speed;
  }

  sim::SimulationConfig config;
  if (roads) {
    const road::Road* road = roads->network().find_road(xodr_road);
    if (!road) {
      std::fprintf(stderr, "no road %s in the file\n", xodr_road.c_str());
      return 2;
    }
    const int index = static_cast<int>(road - roads->network().roads.data());
    const double inner = road->lane_border(xodr_s, xodr_lane > 0 ? xodr_lane - 1 : xodr_lane + 1);
    const double lane_t = 0.5 * (inner + road->lane_border(xodr_s, xodr_lane));
    const sim::TrackFrame f = roads->frame(index, xodr_s);
    const double heading = f.heading_rad + (xodr_lane > 0 ? glm::pi<double>() : 0.0);
    const glm::dvec2 xy = glm::dvec2(f.position) + f.left * lane_t;
    update.vehicle->position_m = glm::dvec3(xy, roads->surface_height({index, xodr_s, lane_t}));
    update.vehicle->position_m.z += lift_m;
    update.vehicle->rotation = {glm::degrees(heading), lift_pitch_deg, 0.0};
    const double v = glm::length(update.vehicle->velocity_mps);
    update.vehicle->velocity_mps = glm::dvec3(std::cos(heading), std::sin(heading), 0.0) * v;
    update.traffic = std::vector<sim::TrafficVehicle>{};
    config.roads = roads;
  }
  if (wipe) return wipe_sequence(out, scenario.seed, update, t, width, height, dash);
  if (spray_drive) {
    if (speed >= 0.0) spray_drive->speed_mps = speed;
    if (update.weather) spray_drive->rain_mm_h = update.weather->rain_rate_mm_h;
    spray_drive->seed = scenario.seed;
  }
  sim::Simulation simulation =
      spray_drive ? testing::drive(*spray_drive) : sim::Simulation(scenario.seed, update, config);
  if (spray_drive) {
    std::printf("spray: %zu parcels, %.2f ml on the glass\n", simulation.spray().particles().size(),
                simulation.spray().ledger().on_glass_m3 * 1e6);
  } else if (dry_after_s >= 0.0 && dry_after_s < t && update.weather) {
    // The rain stops after dry_after_s (the road's water runs off and dries for the rest).
    simulation.advance(dry_after_s);
    sim::Update dry;
    dry.weather = *update.weather;
    dry.weather->rain_rate_mm_h = 0.0;
    simulation.apply(dry);
    simulation.advance(t - dry_after_s);
  } else {
    simulation.advance(t);
  }
  sim::SceneState scene = simulation.state();
  if (spray_drive && update.weather) {
    // The drive keeps its own weather; the sky's options apply to the picture.
    scene.weather.sun_altitude_deg = update.weather->sun_altitude_deg;
    scene.weather.sun_azimuth_deg = update.weather->sun_azimuth_deg;
    scene.weather.cloudiness = update.weather->cloudiness;
    scene.weather.fog_density = update.weather->fog_density;
  }
  if (windshield_metaballs == 0) {
    scene.windshield = testing::golden_windshield(scene.glass);
  } else if (windshield_metaballs > 0) {
    scene.windshield = testing::rainy_windshield(scene.glass, windshield_metaballs, blades);
  }
  if (road_film_mm >= 0.0) {
    scene.road_water = testing::hand_road_water(
        scene.vehicle, road_film_mm,
        puddles ? testing::test_puddles() : std::vector<testing::HandPuddle>{});
  }
  std::printf("car heading %.1f deg (world yaw), sun at %.1f deg high, %.1f deg yaw\n",
              scene.vehicle.rotation.yaw_deg, scene.weather.sun_altitude_deg,
              scene.weather.sun_azimuth_deg);
  std::printf("windshield: %zu metaballs, glass wet fraction %.3f\n",
              scene.windshield.metaballs.size(), scene.windshield.glass_wet_fraction);

  std::vector<NamedView> views;
  for (sim::View view :
       {sim::View::kCockpit, sim::View::kRoad, sim::View::kWindshield, sim::View::kRain}) {
    views.push_back({std::string(sim::view_name(view)), sim::view_spec(view, width, height)});
  }
  if (dash) {
    views.push_back({"COCKPIT_dash", sim::view_spec(sim::View::kCockpit, width, height,
                                                    render::dash_camera_pose())});
  }

  if (measure_frames > 0) {
    std::vector<NamedView> measured;
    for (const NamedView& v : views) {
      if (v.spec.view != sim::View::kRain) measured.push_back(v);
    }
    measure(measured, scene, measure_frames);
    return 0;
  }

  const auto t0 = std::chrono::steady_clock::now();
  auto renderer = render::Renderer::create(g_options);
  const auto t1 = std::chrono::steady_clock::now();
  std::printf("renderer %s, created in %.0f ms\n", renderer->gl_renderer().c_str(),
              std::chrono::duration<double, std::milli>(t1 - t0).count());
  renderer->set_profiling(true);
  renderer->set_relief_shadows(relief);
  for (const NamedView& v : views) {
    render::render_image(*renderer, v.spec, scene);  // the first draw compiles shader variants
    testing::RgbaImage image{width, height, render::render_image(*renderer, v.spec, scene)};
    std::string path = out + "/" + v.name + ".png";
    testing::write_png(path, image);
    std::printf("%s (view wet fraction %.3f):", path.c_str(),
                render::view_wet_fraction(v.spec, scene));
    for (const auto& pass : renderer->last_pass_timings())
      std::printf(" %s %.2f ms", pass.name.c_str(), pass.ms);
    std::printf("\n");
  }
  return 0;
}
