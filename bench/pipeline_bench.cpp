// The benchmark of the standard scene (ARCHITECTURE.md frame budget, QUALITY.md benchmarks):
// per-stage times (sim, render passes, readback, encode), frames per second delivered through the
// real pipeline (render thread + encoder workers) pipelined and serial, and latency from update to
// frame in realtime mode. Prints JSON; reports, never fails on a slow machine.
#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "server/encode/jpeg_encoder.hpp"
#include "server/render/renderer.hpp"
#include "server/session/frame_scheduler.hpp"
#include "server/session/session_registry.hpp"
#include "server/sim/scenario.hpp"

namespace {

using namespace downpour;
using Clock = std::chrono::steady_clock;
using nlohmann::json;

double ms_between(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// Serial stages on this thread: sim step, render, readback and encode, one frame at a time, the
// way the render thread and an encoder worker see them.
json measure_stages(const sim::Scenario& scenario, const sim::ViewSpec& spec, int frames) {
  auto renderer = render::Renderer::create({});
  encode::JpegEncoder encoder;
  sim::Simulation simulation(scenario.seed, scenario.at(0.0));
  std::vector<double> sim_ms, render_ms, readback_ms, encode_ms, frame_ms;
  std::vector<std::uint8_t> pixels;
  const double dt = 1.0 / scenario.fps;
  constexpr int kWarmup = 3;  // the first frames compile shader variants
  for (int i = 0; i < frames + kWarmup; ++i) {
    const auto t0 = Clock::now();
    simulation.apply(scenario.at(simulation.state().sim_time_s + dt));
    simulation.advance(dt);
    const auto t1 = Clock::now();
    const render::PendingReadback pending = renderer->render(1, spec, simulation.state());
    const auto t2 = Clock::now();
    renderer->finish(pending, pixels);
    const auto t3 = Clock::now();
    const std::string jpeg =
        encoder.encode({pixels.data(), spec.width, spec.height}, spec.jpeg_quality);
    const auto t4 = Clock::now();
    if (i < kWarmup) continue;
    sim_ms.push_back(ms_between(t0, t1));
    render_ms.push_back(ms_between(t1, t2));
    readback_ms.push_back(ms_between(t2, t3));
    frame_ms.push_back(ms_between(t1, t3));
    encode_ms.push_back(ms_between(t3, t4));
  }
  json j;
  j["renderer"] = renderer->gl_renderer() + " (EGL " + renderer->platform() + ")";
  j["sim_ms"] = median(sim_ms);
  j["render_submit_ms"] =
      median(render_ms);  // issuing the commands (llvmpipe also rasterizes some)
  j["readback_wait_ms"] = median(readback_ms);
  j["render_thread_ms"] =
      median(frame_ms);  // render + readback: the render thread's time per frame
  j["encode_ms"] = median(encode_ms);
  return j;
}

// Each pass's share of a frame, from a separate renderer that finishes the GPU's work after every
// pass. Finishing mid-frame splits llvmpipe's binned scene, which makes every later frame of that
// context several times slower, so these times only rank the passes; render_thread_ms above is the
// frame's real cost.
json measure_pass_shares(const sim::Scenario& scenario, const sim::ViewSpec& spec, int frames) {
  auto renderer = render::Renderer::create({});
  renderer->set_profiling(true);
  sim::Simulation simulation(scenario.seed, scenario.at(0.0));
  std::map<std::string, std::vector<double>> passes;
  std::vector<std::uint8_t> pixels;
  const double dt = 1.0 / scenario.fps;
  for (int i = 0; i < frames + 3; ++i) {
    simulation.apply(scenario.at(simulation.state().sim_time_s + dt));
    simulation.advance(dt);
    renderer->finish(renderer->render(1, spec, simulation.state()), pixels);
    if (i < 3) continue;
    for (const auto& p : renderer->last_pass_timings()) passes[p.name].push_back(p.ms);
  }
  double total = 0.0;
  std::map<std::string, double> medians;
  for (auto& [name, v] : passes) total += medians[name] = median(v);
  json j;
  for (auto& [name, ms] : medians) j[name] = total > 0.0 ? ms / total : 0.0;
  return j;
}

// The server's pipeline (session registry, render thread, encoder workers) with one session.
struct Pipeline {
  session::SessionRegistry registry{1, [this] { scheduler.wake(); }};
  session::FrameScheduler scheduler{registry, {}};
  std::shared_ptr<session::Session> session;

  Pipeline(const sim::Scenario& scenario, const sim::ViewSpec& spec, sim::Mode mode) {
    scheduler.start();
    session = registry.create({{spec}, mode, scenario.fps, scenario.seed}, scenario.at(0.0));
  }
  ~Pipeline() { stop(); }
  void stop() {
    registry.close_all();
    scheduler.stop();
  }
};

// Frames delivered through the real pipeline, lockstep, keeping `depth` steps in flight (1 =
// serial: render, then encode, then the next step).
json measure_pipeline(const sim::Scenario& scenario, const sim::ViewSpec& spec, int frames,
                      int depth) {
  Pipeline pipeline(scenario, spec, sim::Mode::kLockstep);
  session::Session* s = pipeline.session.get();

  std::mutex m;
  std::condition_variable cv;
  int in_flight = 0, done = 0;
  std::vector<double> latency;
  const double dt = 1.0 / scenario.fps;
  const int warmup = 5;
  Clock::time_point start;
  for (int i = 0; i < frames + warmup; ++i) {
    std::unique_lock lock(m);
    cv.wait(lock, [&] { return in_flight < depth; });
    if (i == warmup) {
      cv.wait(lock, [&] { return in_flight == 0; });
      start = Clock::now();
    }
    ++in_flight;
    lock.unlock();
    const auto submitted = Clock::now();
    s->submit_step(scenario.at((i + 1) * dt), dt, [&, submitted, i](session::StepOutcome) {
      std::lock_guard l(m);
      --in_flight;
      ++done;
      if (i >= warmup) latency.push_back(ms_between(submitted, Clock::now()));
      cv.notify_all();
    });
  }
  std::unique_lock lock(m);
  cv.wait(lock, [&] { return in_flight == 0; });
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  json j;
  j["fps"] = frames / seconds;
  j["step_latency_ms"] = median(latency);
  j["render_ms_median"] = pipeline.scheduler.stats().render_ms_median;
  return j;
}

// A realtime session at the scene's rate, fed an update before every frame: latency from the
// update's arrival to its encoded frame, and the rate actually delivered.
json measure_realtime(const sim::Scenario& scenario, const sim::ViewSpec& spec, double seconds) {
  struct Sink : session::FrameSink {
    std::mutex m;
    std::vector<double> latency;
    int frames = 0;
    void on_frame(const session::FramePtr& f) override {
      std::lock_guard l(m);
      latency.push_back(f->stats.latency_ms);
      ++frames;
    }
    void on_session_closed() override {}
  };
  Pipeline pipeline(scenario, spec, sim::Mode::kRealtime);
  session::Session* s = pipeline.session.get();
  auto sink = std::make_shared<Sink>();
  s->add_sink(sink);
  const auto start = Clock::now();
  // The simulator sends updates at twice the frame rate, as a driving simulator's physics would.
  for (int i = 0; Clock::now() - start < std::chrono::duration<double>(seconds); ++i) {
    s->post_update(scenario.at(i / (2.0 * scenario.fps)));
    std::this_thread::sleep_until(start +
                                  std::chrono::duration<double>((i + 1) / (2.0 * scenario.fps)));
  }
  pipeline.stop();
  std::lock_guard l(sink->m);
  return {{"target_fps", scenario.fps},
          {"fps", sink->frames / seconds},
          {"latency_ms", median(sink->latency)}};
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Downpour benchmark: the standard scene, per stage and end to end, as JSON"};
  std::string scene = "highway_heavy_rain";
  int frames = 120;
  std::vector<std::string> sizes = {"640x360", "1280x720"};
  double realtime_s = 4.0;
  app.add_option("--scene", scene)->check(CLI::IsMember({"highway_heavy_rain", "city_drizzle"}));
  app.add_option("--frames", frames)->check(CLI::Range(10, 100000));
  app.add_option("--sizes", sizes);
  app.add_option("--realtime-seconds", realtime_s);
  CLI11_PARSE(app, argc, argv);

  const sim::Scenario scenario =
      scene == "city_drizzle" ? sim::city_drizzle() : sim::highway_heavy_rain();
  json out;
  out["scene"] = scene;
  out["view"] = "COCKPIT";
  out["frames"] = frames;
  out["hardware_threads"] = std::thread::hardware_concurrency();
  for (const std::string& size : sizes) {
    sim::ViewSpec spec;
    spec.view = sim::View::kCockpit;
    if (std::sscanf(size.c_str(), "%dx%d", &spec.width, &spec.height) != 2) {
      std::fprintf(stderr, "bad size %s\n", size.c_str());
      return 2;
    }
    json r;
    r["size"] = size;
    r["pipelined"] = measure_pipeline(scenario, spec, frames, 3);
    r["stages"] = measure_stages(scenario, spec, frames);
    r["pass_shares"] = measure_pass_shares(scenario, spec, std::min(frames, 30));
    r["serial"] = measure_pipeline(scenario, spec, frames, 1);
    r["realtime"] = measure_realtime(scenario, spec, realtime_s);
    const double bound_ms = std::max(r["stages"]["render_thread_ms"].get<double>(),
                                     r["stages"]["encode_ms"].get<double>());
    r["pipeline_bound_fps"] = 1000.0 / bound_ms;
    r["pipelined_over_bound"] =
        r["pipelined"]["fps"].get<double>() / r["pipeline_bound_fps"].get<double>();
    r["pipelined_over_serial"] =
        r["pipelined"]["fps"].get<double>() / r["serial"]["fps"].get<double>();
    out["results"].push_back(r);
    std::fprintf(stderr, "%s done\n", size.c_str());
  }
  std::printf("%s\n", out.dump(2).c_str());
  return 0;
}
