#include "server/render/warm_up.hpp"

#include <algorithm>
#include <functional>
#include <limits>
#include <memory>
#include <stdexcept>
#include <utility>
#include <vector>

#include "server/render/environment_probe.hpp"
#include "server/render/renderer.hpp"
#include "server/sim/glass_water_surface.hpp"
#include "server/sim/scenario.hpp"
#include "server/sim/simulation.hpp"

namespace downpour::render {
namespace {

// Large enough that the road's near part (its relief) is drawn (at 160x90 it is not).
constexpr int kWidth = 320, kHeight = 180;
constexpr int kMinimalWidth = 64, kMinimalHeight = 36;
constexpr int kFrames = 2;  // a drive's later ticks drawn

std::vector<sim::ViewSpec> every_view(int width = kWidth, int height = kHeight) {
  std::vector<sim::ViewSpec> views;
  for (int v = 0; v < sim::kViewCount; ++v)
    views.push_back(sim::view_spec(static_cast<sim::View>(v), width, height));
  return views;
}

// Every view of a session, drawn as a session's tick draws them (begun, ended, read back), tick
// after tick (the environment's faces and the layers' copies are drawn in turn from the second
// on).
class Session {
 public:
  explicit Session(Renderer& renderer, std::vector<sim::ViewSpec> views = every_view())
      : renderer_(renderer), session_(renderer.open_session()), views_(std::move(views)) {}
  // `ticks` ticks of the first `views` views (all by default).
  void draw(const std::function<const sim::SceneState&()>& next, int ticks, int views = -1) {
    const std::size_t drawn = views < 0 ? views_.size() : static_cast<std::size_t>(views);
    for (int f = 0; f < ticks; ++f)
      draw_tick(renderer_, *session_, views_, drawn, next(), pixels_, truth_);
  }

 private:
  Renderer& renderer_;
  std::unique_ptr<RenderSession> session_;
  std::vector<sim::ViewSpec> views_;
  std::vector<std::uint8_t> pixels_;
  GroundTruthPixels truth_;
};

// A client's picture for view v over one: a flat grey, 30 m away where `depth` (else none).
std::shared_ptr<const sim::ClientImage> picture(sim::View v, bool depth) {
  auto image = std::make_shared<sim::ClientImage>();
  image->width = kWidth;
  image->height = kHeight;
  image->bgrx.assign(static_cast<std::size_t>(kWidth) * kHeight * 4, 128);
  if (depth) image->depth_m.assign(static_cast<std::size_t>(kWidth) * kHeight, 30.0f);
  // Serials no client's picture takes (theirs count up from 1, rpc/validation.cpp): a pass that
  // keeps what it made of a picture by its serial must not take a session's first pictures for
  // these.
  image->serial = std::numeric_limits<std::uint64_t>::max() - 2 * static_cast<std::uint64_t>(v) -
                  (depth ? 0 : 1);
  return image;
}

// The heavy-rain drive with 3 mm standing on the road (a film, puddles in its hollows) behind a
// truck 22 m ahead in the lane, under `weather`, in a session of its own: its first ticks (dry
// glass: the environment drawn whole, then its first face on its own at the seventh), then, if
// `later_s` > 0, a few from then on (drops on the glass, spray behind the truck and the ego car's
// tires) and, with `every_face`, more of the driver's view until each face has been drawn on its
// own (the sky's at the session's 43rd tick).
void draw_wet_drive(Renderer& renderer, const sim::Weather& weather, double later_s,
                    bool every_face = false) {
  const sim::Scenario scenario = sim::highway_heavy_rain();
  sim::SimulationConfig config;
  config.road.initial_m = 0.003;
  auto update = [&](double t) {
    sim::Update u = sim::behind_truck(scenario, t, 22.0);
    u.weather = weather;
    return u;
  };
  sim::Simulation simulation(scenario.seed, update(0.0), config);
  const double dt = 1.0 / scenario.fps;
  double t = 0.0;
  auto tick = [&]() -> const sim::SceneState& {
    t += dt;
    simulation.apply(update(t));
    simulation.advance(dt);
    return simulation.state();
  };
  // The driver's view by itself, its environment drawn whole (every face with the world in it).
  if (renderer.render_image(sim::view_spec(sim::View::kCockpit, kWidth, kHeight), tick()).size() !=
      static_cast<std::size_t>(kWidth) * kHeight * 4)
    throw std::runtime_error("warm-up frame came back empty");
  // A session's first tick, then its seventh, which draws a face on its own (the driver's view
  // alone between them: a tick's first view brings the environment up to date).
  Session session(renderer);
  session.draw(tick, 1);
  session.draw(tick, 6, 1);
  if (later_s <= 0.0) return;
  while (t < later_s - 1e-9) tick();
  session.draw(tick, kFrames);
  if (every_face) {
    // Then the car held where it is (the simulation's ticks are not what is warmed up here), its
    // time going on, until the last face (the sky) has had its turn on its own.
    sim::SceneState held = simulation.state();
    const int ticks = EnvironmentProbe::ticks_until_each_face_alone(EnvironmentConfig{});
    session.draw(
        [&]() -> const sim::SceneState& {
          held.sim_time_s += dt;
          return held;
        },
        ticks - 7 - kFrames, 1);
  }
  // The views that take a client's picture over one, with its depth and the server's haze, and
  // without, each with its clean frame and water mask. (The outputs of the views of the server's
  // world need no variants of their own: the test draws them.)
  for (const bool depth : {true, false}) {
    std::vector<sim::ViewSpec> over;
    sim::ClientImages pictures{};
    for (const sim::View v : {sim::View::kCockpit, sim::View::kRoad, sim::View::kWindshield}) {
      sim::ViewSpec spec = sim::view_spec(v, kWidth, kHeight);
      spec.background = sim::Background::kClient;
      spec.haze = depth;
      spec.outputs.clean = spec.outputs.water_mask = true;
      over.push_back(spec);
      pictures[static_cast<std::size_t>(v)] = picture(v, depth);
    }
    sim::SceneState scene;
    Session(renderer, over)
        .draw(
            [&]() -> const sim::SceneState& {
              scene = tick();
              scene.client_images = pictures;
              return scene;
            },
            kFrames);
  }
}

}  // namespace

void draw_tick(Renderer& renderer, RenderSession& session, const std::vector<sim::ViewSpec>& views,
               std::size_t count, const sim::SceneState& scene, std::vector<std::uint8_t>& pixels,
               GroundTruthPixels& truth) {
  const StepSource stepped = [&]() -> const sim::SceneState& { return scene; };
  std::vector<std::unique_ptr<Renderer::ViewFrame>> begun;
  for (std::size_t v = 0; v < count; ++v)
    begun.push_back(renderer.begin(session, static_cast<int>(v), views[v], scene, stepped));
  std::vector<PendingReadback> pending;
  for (auto& frame : begun) pending.push_back(renderer.end(*frame));
  for (std::size_t v = 0; v < count; ++v) {
    renderer.finish(pending[v], pixels, &truth);
    if (pixels.size() != static_cast<std::size_t>(views[v].width) * views[v].height * 4)
      throw std::runtime_error("a frame came back the wrong size");
  }
}

void warm_up(Renderer& renderer, WarmUp level) {
  // A drop and the blades on dry glass.
  sim::SceneState parked_scene;
  sim::Simulation parked(0, {});
  parked_scene.windshield.metaballs.push_back({700.0f, 400.0f, 3.0f});
  parked_scene.windshield.blades = parked.state().windshield.blades;
  parked_scene.windshield.surface =
      sim::surface_from_metaballs(parked_scene.windshield.metaballs, parked_scene.glass);
  auto parked_tick = [&]() -> const sim::SceneState& { return parked_scene; };
  if (level == WarmUp::kMinimal) {
    Session(renderer, every_view(kMinimalWidth, kMinimalHeight)).draw(parked_tick, 1);
    return;
  }
  Session(renderer).draw(parked_tick, 2);
  const sim::Weather rain = sim::highway_heavy_rain().at(0.0).weather.value_or(sim::Weather{});
  draw_wet_drive(renderer, rain, 1.0);
  sim::Weather night = rain;  // the lamps
  night.sun_altitude_deg = -20.0;
  draw_wet_drive(renderer, night, 1.0, true);  // the sky face alone compiles a variant at night
  sim::Weather low_sun = rain;                 // the relief's shadows
  low_sun.cloudiness = 0.0;
  low_sun.sun_altitude_deg = 10.0;
  draw_wet_drive(renderer, low_sun, 0.0);
}

}  // namespace downpour::render
