#include "server/session/frame_scheduler.hpp"

#include <algorithm>
#include <future>

#include <spdlog/spdlog.h>

#include "server/render/view_wet_fraction.hpp"

namespace downpour::session {
namespace {

constexpr std::size_t kStatsWindow = 512;
constexpr double kMaxRealtimeStepS = 0.25;  // a stalled loop does not make the simulation jump

std::uint64_t target_key(std::uint64_t session_number, int view_index) {
  return session_number * 8 + view_index;
}

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
      if (failed) outcome.error = "encoding a frame failed";
      outcome.frames = std::move(frames);
    }
    done(std::move(outcome));
  }
};

struct FrameScheduler::InFlight {
  render::PendingReadback readback;
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
  Clock::time_point inputs_arrived;
  bool from_earlier_loop = false;
};

FrameScheduler::FrameScheduler(SessionRegistry& registry, SchedulerOptions options)
    : registry_(registry),
      options_(options),
      // Room for two ticks of four views per encoder thread keeps the encoders fed without backlog.
      encoders_(options.encoder_threads, std::max(8, options.encoder_threads * 8)) {
  encoders_.set_on_idle_slot([this] { wake(); });
}

FrameScheduler::~FrameScheduler() { stop(); }

void FrameScheduler::start() {
  std::promise<void> started;
  auto ready = started.get_future();
  thread_ = std::thread([this, &started] { run(&started); });
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
  s.realtime_ticks_skipped = ticks_skipped_;
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
    // Warm-up: a first frame proves the context, shaders and readback before we report ready.
    sim::ViewSpec warm{sim::View::kCockpit, 64, 36, 85, 0.0, std::nullopt};
    const std::vector<std::uint8_t> pixels =
        render::render_image(*renderer_, warm, sim::SceneState{});
    renderer_->release_targets([](std::uint64_t) { return true; });
    if (pixels.size() != 64u * 36u * 4u) throw std::runtime_error("warm-up frame came back empty");
    {
      std::lock_guard lock(stats_mutex_);
      renderer_name_ = renderer_->gl_renderer() + " (EGL " + renderer_->platform() + ")";
    }
    started->set_value();
  } catch (...) {
    renderer_.reset();
    started->set_exception(std::current_exception());
    return;
  }

  while (!stopping_) {
    const auto live = registry_.list();
    const Clock::time_point now = Clock::now();
    bool worked = false;
    Clock::time_point next_wake = now + std::chrono::milliseconds(100);
    for (const auto& s : live) {
      if (s->closed()) continue;
      if (s->config().mode == sim::Mode::kLockstep) {
        worked |= run_lockstep(s);
      } else {
        worked |= run_realtime(s, now);
        next_wake = std::min(next_wake, s->next_due);
      }
    }
    collect(false);
    release_closed_sessions(live);
    if (worked) continue;
    if (!in_flight_.empty()) {
      // Nothing new to render: finish what is in flight rather than wait on the GPU's pace.
      collect(true);
      continue;
    }
    std::unique_lock lock(wake_mutex_);
    wake_cv_.wait_until(lock, next_wake, [&] { return woken_ || stopping_.load(); });
    woken_ = false;
  }
  collect(true);
  renderer_.reset();
}

bool FrameScheduler::run_lockstep(const std::shared_ptr<Session>& s) {
  const int views = static_cast<int>(s->config().views.size());
  if (!encoders_.try_reserve(views)) return false;  // the encoder's completion wakes us
  while (auto job = s->pop_job()) {
    s->simulation().apply(job->update);
    if (job->dt_s <= 0.0) continue;  // update only
    tick(s, job->dt_s, std::move(job->done), job->arrived);
    return true;
  }
  encoders_.release_reservation(views);
  return false;
}

bool FrameScheduler::run_realtime(const std::shared_ptr<Session>& s, Clock::time_point now) {
  const auto period = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(1.0 / s->config().fps));
  if (s->last_tick == Clock::time_point{}) {
    s->last_tick = now - period;
    s->next_due = now;
  }
  if (now < s->next_due) return false;
  s->next_due += period;
  if (s->next_due < now)
    s->next_due = now + period;  // fell behind: do not try to catch up in a burst
  if (!encoders_.try_reserve(static_cast<int>(s->config().views.size()))) {
    ++ticks_skipped_;
    return false;
  }
  Clock::time_point arrived = now;
  if (auto update = s->take_update()) {
    s->simulation().apply(update->first);
    arrived = update->second;
  }
  const double dt =
      std::min(std::chrono::duration<double>(now - s->last_tick).count(), kMaxRealtimeStepS);
  s->last_tick = now;
  tick(s, dt, nullptr, arrived);
  return true;
}

void FrameScheduler::tick(const std::shared_ptr<Session>& s, double dt_s, StepDone done,
                          Clock::time_point inputs_arrived) {
  s->simulation().advance(dt_s);
  s->note_sim_time();
  const sim::SceneState& scene = s->simulation().state();
  const std::uint64_t frame_number = s->begin_frame();
  const auto& views = s->config().views;
  auto collector = std::make_shared<TickCollector>();
  collector->frames.resize(views.size());
  collector->remaining = static_cast<int>(views.size());
  collector->done = std::move(done);
  for (std::size_t i = 0; i < views.size(); ++i) {
    const Clock::time_point t0 = Clock::now();
    InFlight f;
    f.readback = renderer_->render(target_key(s->number(), static_cast<int>(i)), views[i], scene);
    f.render_ms = ms_since(t0);
    f.session = s;
    f.collector = collector;
    f.view_index = static_cast<int>(i);
    f.frame_number = frame_number;
    f.sim_time_s = scene.sim_time_s;
    f.client_time_s = scene.client_time_s;
    f.drops_on_glass = scene.windshield.drops + scene.windshield.particles;
    f.glass_wet_fraction = scene.windshield.glass_wet_fraction;
    f.view_wet_fraction = render::view_wet_fraction(views[i], scene);
    f.inputs_arrived = inputs_arrived;
    in_flight_.push_back(std::move(f));
    ++frames_rendered_;
    std::lock_guard lock(stats_mutex_);
    record(render_ms_window_, render_ms_next_, in_flight_.back().render_ms);
    if (options_.profile_passes) pass_timings_ = renderer_->last_pass_timings();
  }
}

void FrameScheduler::collect(bool force_all) {
  std::vector<InFlight> waiting;
  for (InFlight& f : in_flight_) {
    // A readback from an earlier loop is finished now (waiting if needed): each target has only
    // two readback slots.
    if (!force_all && !f.from_earlier_loop && !renderer_->is_ready(f.readback)) {
      f.from_earlier_loop = true;
      waiting.push_back(std::move(f));
      continue;
    }
    const Clock::time_point t0 = Clock::now();
    const std::size_t bytes = static_cast<std::size_t>(f.readback.width) * f.readback.height * 4;
    std::vector<std::uint8_t> pixels = encoders_.take_buffer(bytes);
    renderer_->finish(f.readback, pixels);
    const double readback_ms = ms_since(t0);
    const sim::ViewSpec& spec = f.session->config().views[f.view_index];
    encode::EncodeJob job;
    job.rgba = std::move(pixels);
    job.width = spec.width;
    job.height = spec.height;
    job.quality = spec.jpeg_quality;
    job.done = [this, f = std::move(f), readback_ms, spec](std::string jpeg, double encode_ms) {
      if (jpeg.empty()) {
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
      frame->jpeg = std::move(jpeg);
      frame->stats.render_ms = f.render_ms;
      frame->stats.readback_ms = readback_ms;
      frame->stats.encode_ms = encode_ms;
      frame->stats.latency_ms = ms_since(f.inputs_arrived);
      frame->stats.drops_on_glass = f.drops_on_glass;
      frame->stats.glass_wet_fraction = f.glass_wet_fraction;
      frame->stats.view_wet_fraction = f.view_wet_fraction;
      ++frames_encoded_;
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
  in_flight_ = std::move(waiting);
}

void FrameScheduler::release_closed_sessions(const std::vector<std::shared_ptr<Session>>& live) {
  std::vector<std::uint64_t> now_live;
  for (const auto& s : live) now_live.push_back(s->number());
  for (std::uint64_t number : known_sessions_) {
    if (std::find(now_live.begin(), now_live.end(), number) != now_live.end()) continue;
    const bool busy = std::any_of(in_flight_.begin(), in_flight_.end(),
                                  [&](const InFlight& f) { return f.session->number() == number; });
    if (busy) {
      now_live.push_back(number);  // release once its readbacks are done
      continue;
    }
    renderer_->release_targets([&](std::uint64_t key) { return key / 8 == number; });
  }
  known_sessions_ = std::move(now_live);
}

}  // namespace downpour::session
