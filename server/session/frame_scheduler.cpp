#include "server/session/frame_scheduler.hpp"

#include <malloc.h>

#include <algorithm>
#include <future>
#include <thread>

#include <spdlog/spdlog.h>

#include "server/render/cpu/atmosphere.hpp"
#include "server/render/cpu/view_road_states.hpp"
#include "server/render/cpu/view_wet_fraction.hpp"
#include "server/render/warm_up.hpp"

namespace downpour::session {
namespace {

constexpr std::size_t kStatsWindow = 512;
constexpr auto kIdleWake = std::chrono::milliseconds(100);
constexpr auto kStatsPeriod = std::chrono::milliseconds(100);  // sessions' tick stats published

double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

}  // namespace

// The views of one tick on their way to the encoders; completes the step when the last is done.
struct FrameScheduler::TickCollector {
  std::mutex mutex;
  std::vector<FramePtr> frames;  // guarded by mutex
  int remaining = 0;             // guarded by mutex
  bool failed = false;           // guarded by mutex
  StepDone done;

  void add(int index, FramePtr frame) {
    StepOutcome outcome;
    {
      std::lock_guard lock(mutex);
      if (frame) {
        frames[index] = std::move(frame);
      } else {
        failed = true;
      }
      if (--remaining > 0 || !done) return;
      outcome.ok = !failed;
      if (failed) outcome.error = "a frame failed";  // failure: kFailed (the log says how)
      outcome.frames = std::move(frames);
    }
    done(std::move(outcome));
  }
};

// A view's frame between its render and its encoding.
struct FrameScheduler::InFlight {
  std::shared_ptr<Session> session;
  std::shared_ptr<TickCollector> collector;
  int view_index = 0;
  std::uint64_t frame_number = 0;
  double sim_time_s = 0.0;
  double client_time_s = 0.0;
  double render_ms = 0.0;
  std::uint32_t drops_on_glass = 0;
  double glass_wet_fraction = 0.0;
  double view_wet_fraction = 0.0;
  std::array<double, 4> road_states{};
  std::uint32_t rain_streaks = 0;
  std::uint64_t background_repeats = 0;
  double visibility_m = 0.0;
  std::array<sim::TireWater, sim::kTires> tires{};
  sim::EgoPlace ego_place;
  Clock::time_point inputs_arrived;
};

FrameScheduler::FrameScheduler(SessionRegistry& registry, SchedulerOptions options)
    : registry_(registry),
      options_(options),
      world_worker_(make_world_worker(options.step_helper)),
      // Room for two ticks of four views per encoder thread keeps the encoders fed without backlog.
      encoders_(options.encoder_threads, std::max(8, options.encoder_threads * 8)) {
  encoders_.set_on_idle_slot([this] { wake(); });
}

FrameScheduler::~FrameScheduler() { stop(); }

void FrameScheduler::start() {
  std::promise<void> started;
  auto ready = started.get_future();
  thread_ = std::thread([this, &started] {
    sim::name_this_thread("dp-render");
    run(&started);
  });
  try {
    ready.get();
  } catch (...) {
    thread_.join();
    throw;
  }
}

void FrameScheduler::stop() {
  if (!thread_.joinable()) return;
  stopping_ = true;
  wake();
  thread_.join();
}

void FrameScheduler::wake() {
  {
    std::lock_guard lock(wake_mutex_);
    woken_ = true;
  }
  wake_cv_.notify_one();
}

void FrameScheduler::record(std::vector<double>& window, std::size_t& next, double value) {
  if (window.size() < kStatsWindow) {
    window.push_back(value);
  } else {
    window[next] = value;
  }
  next = (next + 1) % kStatsWindow;
}

SchedulerStats FrameScheduler::stats() const {
  SchedulerStats s;
  std::lock_guard lock(stats_mutex_);
  s.renderer = renderer_name_;
  s.frames_rendered = frames_rendered_;
  s.frames_encoded = frames_encoded_;
  s.realtime_frames_late = frames_late_;
  s.render_ms_median = median(render_ms_window_);
  s.encode_ms_median = median(encode_ms_window_);
  s.encoder_threads = encoders_.threads();
  return s;
}

std::vector<render::PassTiming> FrameScheduler::last_pass_timings() const {
  std::lock_guard lock(stats_mutex_);
  return pass_timings_;
}

void FrameScheduler::run(std::promise<void>* started) {
  try {
    renderer_ = render::Renderer::create(options_.renderer);
    renderer_->set_profiling(options_.profile_passes);
    readbacks_ = std::make_unique<render::ReadbackQueue<InFlight>>(
        *renderer_, [this](std::size_t bytes) { return encoders_.take_buffer(bytes); });
    // Warm-up: first frames prove the context, shaders and readback before we report ready, and
    // have llvmpipe compile the shader variants the sessions' passes will pick rather than stall
    // their streams (warm_up.hpp).
    const auto warm_up_start = Clock::now();
    render::warm_up(*renderer_, options_.warm_up);
    spdlog::info("renderer warmed up ({}) in {:.1f} s",
                 options_.warm_up == render::WarmUp::kFull ? "full" : "minimal",
                 std::chrono::duration<double>(Clock::now() - warm_up_start).count());
    {
      std::lock_guard lock(stats_mutex_);
      renderer_name_ = renderer_->gl_renderer() + " (EGL " + renderer_->platform() + ")";
    }
    started->set_value();
  } catch (...) {
    readbacks_.reset();
    renderer_.reset();
    started->set_exception(std::current_exception());
    return;
  }

  while (!stopping_) {
    const Clock::time_point now = Clock::now();
    heartbeat_ = now.time_since_epoch().count();
    try {
      loop_once(now);
    } catch (const std::exception& e) {
      // Not one session's (those are caught nearer): log, and keep the loop and the others going.
      spdlog::critical("render loop: {}", e.what());
      std::this_thread::sleep_for(kIdleWake);
    }
  }
  drop_step_ahead(EndReason::kShuttingDown, "the server is stopping");
  collect(true);
  readbacks_.reset();
  render_sessions_.clear();
  renderer_.reset();
}

double FrameScheduler::stalled_s(Clock::time_point now) const {
  const Clock::rep beat = heartbeat_.load();
  if (beat == 0) return 0.0;
  return std::max(
      0.0, std::chrono::duration<double>(now - Clock::time_point(Clock::duration(beat))).count());
}

void FrameScheduler::loop_once(Clock::time_point now) {
  sync_sessions(now);
  // A lockstep session is due once a step waits; any session renders only if the encoders have
  // room for its views (the render thread never waits for them: their completion wakes it).
  const auto tick = policy_.next(
      now,
      [this](std::uint64_t id) -> std::optional<Clock::time_point> {
        if (ahead_ && ahead_->session->number() == id) return ahead_->job.arrived;
        return live_.at(id)->oldest_step_arrival();
      },
      [this](std::uint64_t id) {
        return encoders_.try_reserve(static_cast<int>(live_.at(id)->config().views.size()));
      });
  if (tick) {
    const std::shared_ptr<Session> s = live_.at(tick->session);
    const Clock::time_point started = Clock::now();
    try {
      run_tick(*tick);
      // Its share of the loop is counted in the render thread's time its tick took.
      policy_.charge(tick->session, std::chrono::duration<double>(Clock::now() - started).count());
    } catch (const std::exception& e) {
      // One session's failed frame (a render target it asked for, its step) ends that session,
      // not the server.
      spdlog::error("session {}: a frame failed ({}); closing the session", s->id(), e.what());
      registry_.close(s->id(), {EndReason::kFailed,
                                "session " + s->id() + " failed and was closed: " + e.what()});
    }
    collect(false);
    return;
  }
  collect(false);
  if (!readbacks_->empty()) {
    // Nothing new to render: finish what is in flight rather than wait on the GPU's pace.
    collect(true);
    return;
  }
  std::unique_lock lock(wake_mutex_);
  wake_cv_.wait_until(lock, policy_.next_wake(now, kIdleWake),
                      [&] { return woken_ || stopping_.load(); });
  woken_ = false;
}

void FrameScheduler::drop_step_ahead(EndReason reason, const std::string& why) {
  if (!ahead_) return;
  step_worker_.wait();
  if (ahead_->job.done) ahead_->job.done({false, why, reason, {}});
  ahead_.reset();
}

void FrameScheduler::sync_sessions(Clock::time_point now) {
  for (const auto& s : registry_.close_idle(now)) {
    spdlog::info("session {} closed: no client heard for {:g} s (--session-idle-timeout-s)",
                 s->id(), registry_.idle_timeout_s());
  }
  std::map<std::uint64_t, std::shared_ptr<Session>> live;
  for (auto& s : registry_.list()) {
    if (s->closed()) continue;
    const std::uint64_t id = s->number();
    if (!policy_.contains(id)) policy_.add(id, s->config().mode, s->config().fps, now);
    s->drop_cancelled();
    live.emplace(id, std::move(s));
  }
  for (const auto& [id, s] : live_) {
    if (live.count(id)) continue;
    frames_late_closed_ += policy_.stats(id, now).frames_late;  // the server's total keeps them
    policy_.remove(id);
  }
  live_ = std::move(live);
  if (ahead_ && !live_.count(ahead_->session->number()))
    drop_step_ahead(EndReason::kClosed, "session " + ahead_->session->id() + " was closed");
  // A closed session's render targets go once no readback of them is in flight; then the shared
  // targets and buffers sized for it, and the heap's free pages go back to the system.
  bool released = false;
  for (auto it = render_sessions_.begin(); it != render_sessions_.end();) {
    const bool gone = !live_.count(it->first) && !readbacks_->holds(it->second.get());
    released |= gone;
    it = gone ? render_sessions_.erase(it) : std::next(it);
  }
  if (released) {
    renderer_->release_shared_targets();
    encoders_.release_spare_buffers();
    malloc_trim(0);
  }
  if (now - stats_published_ >= kStatsPeriod) {
    stats_published_ = now;
    std::uint64_t late = frames_late_closed_;
    for (const auto& [id, s] : live_) {
      const TickStats t = policy_.stats(id, now);
      s->set_tick_stats(t);
      late += t.frames_late;
    }
    frames_late_ = late;
  }
}

void FrameScheduler::run_tick(const TickPolicy::Tick& t) {
  const std::shared_ptr<Session>& s = live_.at(t.session);
  const int views = static_cast<int>(s->config().views.size());
  // The encoders' room for this tick's views: tick() gives back what it does not render.
  bool ticked = false;
  try {
    if (s->config().mode == sim::Mode::kRealtime) {
      Clock::time_point arrived = Clock::now();
      if (auto update = s->take_update()) {
        s->simulation().apply(update->first);
        arrived = update->second;
      }
      const StartedStep step = start_step(*s, t.dt_s);
      ticked = true;
      tick(s, step, nullptr, arrived);
      return;
    }
    if (ahead_ && ahead_->session == s) {  // its step has been running since its last tick
      StepAhead ahead = std::move(*ahead_);
      ahead_.reset();
      ticked = true;
      tick(s, ahead.step, std::move(ahead.job.done), ahead.job.arrived);
    } else if (auto job = pop_step(*s)) {
      StepDone done = std::move(job->done);
      StartedStep step;
      try {
        step = start_step(*s, job->dt_s);
      } catch (...) {
        if (done) done({false, "the step could not start", EndReason::kFailed, {}});
        throw;
      }
      ticked = true;
      tick(s, step, std::move(done), job->arrived);
    } else {
      encoders_.release_reservation(views);  // the session was closed meanwhile
      return;
    }
  } catch (...) {
    if (!ticked) encoders_.release_reservation(views);
    throw;
  }
  // The session's next step, if it is already queued, runs while this one's frames are read
  // back and encoded and while other sessions render.
  if (!ahead_) {
    if (auto job = pop_step(*s)) {
      ahead_ = StepAhead{s, std::move(*job), {}};
      ahead_->step = start_step(*s, ahead_->job.dt_s);
    }
  }
}

std::optional<StepJob> FrameScheduler::pop_step(Session& s) {
  // The updates queued before the step apply first, in order; updates alone wait for a step.
  if (!s.oldest_step_arrival()) return std::nullopt;
  while (auto job = s.pop_job()) {
    step_worker_.wait();  // a step started ahead may still be running on this simulation
    s.simulation().apply(job->update);
    if (job->dt_s > 0.0) return job;
  }
  return std::nullopt;
}

std::unique_ptr<sim::WorkerThread> FrameScheduler::make_world_worker(bool wanted) {
  if (!wanted || sim::usable_cores() < 2) return nullptr;
  return std::make_unique<sim::WorkerThread>("dp-world");
}

FrameScheduler::StartedStep FrameScheduler::start_step(Session& s, double dt_s) {
  step_worker_.wait();  // one step at a time: another session's, started ahead, finishes first
  sim::Simulation& simulation = s.simulation();
  StartedStep step;
  step.inputs = simulation.inputs_after(dt_s);
  step.failure = std::make_shared<std::exception_ptr>();
  // What the step throws is kept for the tick that waits for it (and rethrown there).
  step_worker_.start([&simulation, dt_s, failure = step.failure, helper = world_worker_.get()] {
    try {
      simulation.advance(dt_s, helper);
    } catch (...) {
      *failure = std::current_exception();
    }
  });
  return step;
}

void FrameScheduler::tick(const std::shared_ptr<Session>& s, const StartedStep& step, StepDone done,
                          Clock::time_point inputs_arrived) {
  // The water steps on its own thread while the scene's passes, which need only the frame's
  // inputs, are drawn; a pass that needs the water waits for it.
  const sim::SceneState& inputs = step.inputs;
  sim::Simulation& simulation = s->simulation();
  bool stepped = false;
  const render::StepSource water = [&]() -> const sim::SceneState& {
    if (!stepped) {
      step_worker_.wait();
      stepped = true;
      if (step.failure && *step.failure) std::rethrow_exception(*step.failure);
    }
    return simulation.state();
  };
  const std::uint64_t frame_number = s->begin_frame();
  const auto& views = s->config().views;
  auto collector = std::make_shared<TickCollector>();
  collector->frames.resize(views.size());
  collector->remaining = static_cast<int>(views.size());
  collector->done = std::move(done);
  std::vector<std::pair<render::PendingReadback, InFlight>> rendered;
  try {
    std::unique_ptr<render::RenderSession>& targets = render_sessions_[s->number()];
    if (!targets) targets = renderer_->open_session();
    // The same air for every view of the tick.
    const double visibility_m = render::visibility_m(render::atmosphere_from(inputs.weather));
    // Every view's passes that need only the inputs first, then the rest of each: one view's
    // wait for the step and its CPU work (the rain layer) overlap the others' rasterizing.
    std::vector<std::unique_ptr<render::Renderer::ViewFrame>> begun;
    std::vector<double> begin_ms;
    for (std::size_t i = 0; i < views.size(); ++i) {
      const Clock::time_point t0 = Clock::now();
      begun.push_back(renderer_->begin(*targets, static_cast<int>(i), views[i], inputs, water,
                                       views.size() > 1));
      begin_ms.push_back(ms_since(t0));
    }
    for (std::size_t i = 0; i < views.size(); ++i) {
      const Clock::time_point t0 = Clock::now();
      InFlight f;
      const render::PendingReadback readback = renderer_->end(*begun[i]);
      f.render_ms = begin_ms[i] + ms_since(t0);
      f.rain_streaks = renderer_->last_rain_streaks();
      if (views[i].background == sim::Background::kClient) {
        f.background_repeats = s->note_background(
            views[i].view, inputs.client_images[static_cast<std::size_t>(views[i].view)].get());
      }
      f.visibility_m = visibility_m;
      f.session = s;
      f.collector = collector;
      f.view_index = static_cast<int>(i);
      f.frame_number = frame_number;
      f.sim_time_s = inputs.sim_time_s;
      f.client_time_s = inputs.client_time_s;
      f.inputs_arrived = inputs_arrived;
      ++frames_rendered_;
      if (options_.observer) options_.observer->rendered(f.render_ms);
      std::lock_guard lock(stats_mutex_);
      record(render_ms_window_, render_ms_next_, f.render_ms);
      if (options_.profile_passes) pass_timings_ = renderer_->last_pass_timings();
      rendered.emplace_back(readback, std::move(f));
    }
    water();  // views that drew no water still wait for the step: the next tick builds on it
  } catch (...) {
    // The step must not outlive this call; the views rendered go on to the encoders (their
    // readbacks are in flight), the others fail the step and give back their encoder room.
    step_worker_.wait();
    for (auto& [readback, f] : rendered) readbacks_->push(readback, std::move(f));
    const int missing = static_cast<int>(views.size() - rendered.size());
    encoders_.release_reservation(missing);
    for (std::size_t i = rendered.size(); i < views.size(); ++i)
      collector->add(static_cast<int>(i), nullptr);
    throw;
  }
  s->note_sim_time();
  const sim::SceneState& scene = simulation.state();
  for (auto& [readback, f] : rendered) {
    f.drops_on_glass = scene.windshield.drops + scene.windshield.particles;
    f.glass_wet_fraction = scene.windshield.glass_wet_fraction;
    f.view_wet_fraction = render::view_wet_fraction(views[f.view_index], scene);
    const render::RoadStateFractions road = render::view_road_states(views[f.view_index], scene);
    f.road_states = {road.dry, road.wet, road.drench, road.puddle};
    f.tires = scene.tires;
    f.ego_place = scene.ego_place;
    readbacks_->push(readback, std::move(f));
  }
}

void FrameScheduler::collect(bool all) {
  readbacks_->collect(
      all,
      [this](InFlight f, std::vector<std::uint8_t> pixels, render::GroundTruthPixels truth,
             double wait_ms) {
        encode(std::move(f), std::move(pixels), std::move(truth), wait_ms);
      },
      [this](InFlight f, const std::string& what) {
        // The frame is lost: its step fails and its session ends; the other sessions go on.
        spdlog::error("session {}: reading frame {} back failed ({}); closing the session",
                      f.session->id(), f.frame_number, what);
        f.collector->add(f.view_index, nullptr);
        registry_.close(
            f.session->id(),
            {EndReason::kFailed, "session " + f.session->id() + " failed and was closed: " + what});
      });
}

void FrameScheduler::encode(InFlight f, std::vector<std::uint8_t> pixels,
                            render::GroundTruthPixels truth, double readback_ms) {
  const sim::ViewSpec& spec = f.session->config().views[f.view_index];
  encode::EncodeJob job;
  job.rgba = std::move(pixels);
  job.width = spec.width;
  job.height = spec.height;
  job.quality = spec.jpeg_quality;
  job.clean = std::move(truth.clean);
  job.clean_jpeg = spec.outputs.clean;
  job.water_mask = spec.outputs.water_mask;
  job.depth_m = std::move(truth.depth_m);
  job.done = [this, f = std::move(f), readback_ms, spec](encode::EncodedImages images,
                                                         double encode_ms) {
    if (images.jpeg.empty()) {
      spdlog::error("session {}: encoding frame {} failed", f.session->id(), f.frame_number);
      f.collector->add(f.view_index, nullptr);
      return;
    }
    auto frame = std::make_shared<EncodedFrame>();
    frame->session_id = f.session->id();
    frame->frame_number = f.frame_number;
    frame->sim_time_s = f.sim_time_s;
    frame->client_time_s = f.client_time_s;
    frame->view = spec.view;
    frame->width = spec.width;
    frame->height = spec.height;
    frame->jpeg = std::move(images.jpeg);
    frame->clean_jpeg = std::move(images.clean_jpeg);
    frame->water_mask_png = std::move(images.water_mask_png);
    frame->depth_png = std::move(images.depth_png);
    frame->stats.render_ms = f.render_ms;
    frame->stats.readback_ms = readback_ms;
    frame->stats.encode_ms = encode_ms;
    frame->stats.latency_ms = ms_since(f.inputs_arrived);
    frame->stats.drops_on_glass = f.drops_on_glass;
    frame->stats.glass_wet_fraction = f.glass_wet_fraction;
    frame->stats.view_wet_fraction = f.view_wet_fraction;
    frame->stats.road_states = f.road_states;
    frame->stats.rain_streaks = f.rain_streaks;
    frame->stats.background_repeats = f.background_repeats;
    frame->stats.visibility_m = f.visibility_m;
    frame->tires = f.tires;
    frame->ego_place = f.ego_place;
    ++frames_encoded_;
    if (options_.observer) options_.observer->encoded(encode_ms, frame->stats.latency_ms);
    {
      std::lock_guard lock(stats_mutex_);
      record(encode_ms_window_, encode_ms_next_, encode_ms);
    }
    FramePtr shared = std::move(frame);
    f.session->publish(shared);
    f.collector->add(f.view_index, std::move(shared));
  };
  encoders_.submit(std::move(job));
}

}  // namespace downpour::session
