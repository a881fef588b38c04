#include "server/session/session.hpp"

#include <algorithm>

namespace downpour::session {

namespace {

sim::SimulationConfig simulation_config(const SessionConfig& config) {
  sim::SimulationConfig c;
  c.roads = config.roads;
  c.ego = config.ego;
  c.windshield.glass = config.glass;
  return c;
}

}  // namespace

Session::Session(std::string id, std::uint64_t number, SessionConfig config,
                 const sim::Update& initial, std::function<void()> wake_renderer)
    : id_(std::move(id)),
      number_(number),
      config_(std::move(config)),
      wake_renderer_(std::move(wake_renderer)),
      simulation_(config_.seed, initial, simulation_config(config_)),
      last_heard_(Clock::now().time_since_epoch().count()) {}

void Session::touch() { last_heard_ = Clock::now().time_since_epoch().count(); }

void Session::attach_stream() {
  ++streams_;
  touch();
}

void Session::detach_stream() {
  --streams_;
  touch();  // the lease runs from the stream's end
}

double Session::idle_s(Clock::time_point now) const {
  if (streams_.load() > 0) return 0.0;
  const Clock::time_point heard{Clock::duration(last_heard_.load())};
  return std::max(0.0, std::chrono::duration<double>(now - heard).count());
}

Session::Submit Session::post_update(const sim::Update& update) {
  std::vector<StepJob> dropped;
  Submit result = Submit::kQueued;
  {
    std::lock_guard lock(mutex_);
    if (closed_) return Submit::kClosed;
    if (config_.mode == sim::Mode::kLockstep) {
      take_cancelled(&dropped);
      if (!jobs_.empty() && jobs_.back().dt_s <= 0.0) {
        jobs_.back().update.merge_from(update);
      } else if (jobs_.size() >= kMaxQueuedJobs) {
        result = Submit::kFull;
      } else {
        jobs_.push_back({update, 0.0, nullptr, Clock::now(), {}});
      }
    } else {
      if (inbox_) {
        inbox_->merge_from(update);
      } else {
        inbox_ = update;
      }
      inbox_arrived_ = Clock::now();
    }
  }
  fail_cancelled(std::move(dropped));
  if (result == Submit::kQueued) wake_renderer_();
  return result;
}

Session::Submit Session::submit_step(sim::Update update, double dt_s, StepDone done,
                                     CancelFlag cancelled) {
  std::vector<StepJob> dropped;
  Submit result = Submit::kQueued;
  {
    std::lock_guard lock(mutex_);
    if (closed_) return Submit::kClosed;
    take_cancelled(&dropped);
    if (jobs_.size() >= kMaxQueuedJobs) {
      result = Submit::kFull;
    } else {
      jobs_.push_back(
          {std::move(update), dt_s, std::move(done), Clock::now(), std::move(cancelled)});
    }
  }
  fail_cancelled(std::move(dropped));
  if (result == Submit::kQueued) wake_renderer_();
  return result;
}

void Session::take_cancelled(std::vector<StepJob>* out) {
  for (auto it = jobs_.begin(); it != jobs_.end();) {
    if (it->is_cancelled()) {
      out->push_back(std::move(*it));
      it = jobs_.erase(it);
    } else {
      ++it;
    }
  }
}

void Session::fail_cancelled(std::vector<StepJob> jobs) {
  steps_cancelled_ += jobs.size();
  for (StepJob& job : jobs) {
    if (job.done) {
      job.done(
          {false, "the step's call was cancelled before it started", EndReason::kCancelled, {}});
    }
  }
}

void Session::add_sink(const std::shared_ptr<FrameSink>& sink) {
  bool was_closed = false;
  SessionEnd end;
  {
    std::lock_guard lock(mutex_);
    was_closed = closed_;
    if (!was_closed) sinks_.push_back(sink);
    end = end_;
  }
  if (was_closed) sink->on_session_closed(end);
}

void Session::remove_sink(const FrameSink* sink) {
  std::lock_guard lock(mutex_);
  std::erase_if(sinks_, [&](const std::weak_ptr<FrameSink>& w) {
    const auto s = w.lock();
    return !s || s.get() == sink;
  });
}

void Session::close(const SessionEnd& end) {
  std::deque<StepJob> jobs;
  std::vector<std::weak_ptr<FrameSink>> sinks;
  {
    std::lock_guard lock(mutex_);
    if (closed_.exchange(true)) return;
    end_ = end;
    jobs.swap(jobs_);
    sinks.swap(sinks_);
  }
  const std::string why = end.message.empty() ? "session " + id_ + " was closed" : end.message;
  for (StepJob& job : jobs) {
    if (job.done) job.done({false, why, end.reason, {}});
  }
  for (const auto& w : sinks) {
    if (const auto s = w.lock()) s->on_session_closed(end);
  }
  wake_renderer_();
}

std::optional<Clock::time_point> Session::oldest_step_arrival() const {
  std::lock_guard lock(mutex_);
  for (const StepJob& job : jobs_) {
    if (job.dt_s > 0.0 && !job.is_cancelled()) return job.arrived;
  }
  return std::nullopt;
}

TickStats Session::tick_stats() const {
  std::lock_guard lock(mutex_);
  return tick_stats_;
}

void Session::set_tick_stats(const TickStats& stats) {
  std::lock_guard lock(mutex_);
  tick_stats_ = stats;
}

std::optional<StepJob> Session::pop_job() {
  std::vector<StepJob> dropped;
  std::optional<StepJob> job;
  {
    std::lock_guard lock(mutex_);
    take_cancelled(&dropped);
    if (!jobs_.empty()) {
      job = std::move(jobs_.front());
      jobs_.pop_front();
    }
  }
  fail_cancelled(std::move(dropped));
  return job;
}

void Session::drop_cancelled() {
  std::vector<StepJob> dropped;
  {
    std::lock_guard lock(mutex_);
    take_cancelled(&dropped);
  }
  fail_cancelled(std::move(dropped));
}

std::optional<std::pair<sim::Update, Clock::time_point>> Session::take_update() {
  std::lock_guard lock(mutex_);
  if (!inbox_) return std::nullopt;
  auto out = std::make_pair(std::move(*inbox_), inbox_arrived_);
  inbox_.reset();
  return out;
}

std::uint64_t Session::begin_frame() {
  frames_rendered_.fetch_add(1);
  return next_frame_++;
}

void Session::publish(const FramePtr& frame) {
  std::vector<std::shared_ptr<FrameSink>> sinks;
  {
    std::lock_guard lock(mutex_);
    for (const auto& w : sinks_) {
      if (auto s = w.lock()) sinks.push_back(std::move(s));
    }
  }
  for (const auto& s : sinks) s->on_frame(frame);
}

std::uint64_t Session::note_background(sim::View view, const sim::ClientImage* image) {
  const auto v = static_cast<std::size_t>(view);
  if (!image || image->serial == background_drawn_[v]) {
    ++background_repeats_[v];
  } else {
    background_drawn_[v] = image->serial;
  }
  return background_repeats_[v];
}

}  // namespace downpour::session
