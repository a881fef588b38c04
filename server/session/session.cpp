#include "server/session/session.hpp"

#include <algorithm>

namespace downpour::session {

Session::Session(std::string id, std::uint64_t number, SessionConfig config,
                 const sim::Update& initial, std::function<void()> wake_renderer)
    : id_(std::move(id)),
      number_(number),
      config_(std::move(config)),
      wake_renderer_(std::move(wake_renderer)),
      simulation_(config_.seed, initial) {}

Session::Submit Session::post_update(const sim::Update& update) {
  {
    std::lock_guard lock(mutex_);
    if (closed_) return Submit::kClosed;
    if (config_.mode == sim::Mode::kLockstep) {
      if (jobs_.size() >= kMaxQueuedJobs) return Submit::kFull;
      jobs_.push_back({update, 0.0, nullptr, Clock::now()});
    } else {
      if (inbox_) {
        inbox_->merge_from(update);
      } else {
        inbox_ = update;
      }
      inbox_arrived_ = Clock::now();
    }
  }
  wake_renderer_();
  return Submit::kQueued;
}

Session::Submit Session::submit_step(sim::Update update, double dt_s, StepDone done) {
  {
    std::lock_guard lock(mutex_);
    if (closed_) return Submit::kClosed;
    if (jobs_.size() >= kMaxQueuedJobs) return Submit::kFull;
    jobs_.push_back({std::move(update), dt_s, std::move(done), Clock::now()});
  }
  wake_renderer_();
  return Submit::kQueued;
}

void Session::add_sink(const std::shared_ptr<FrameSink>& sink) {
  bool was_closed = false;
  {
    std::lock_guard lock(mutex_);
    was_closed = closed_;
    if (!was_closed) sinks_.push_back(sink);
  }
  if (was_closed) sink->on_session_closed();
}

void Session::remove_sink(const FrameSink* sink) {
  std::lock_guard lock(mutex_);
  std::erase_if(sinks_, [&](const std::weak_ptr<FrameSink>& w) {
    const auto s = w.lock();
    return !s || s.get() == sink;
  });
}

void Session::close() {
  std::deque<StepJob> jobs;
  std::vector<std::weak_ptr<FrameSink>> sinks;
  {
    std::lock_guard lock(mutex_);
    if (closed_.exchange(true)) return;
    jobs.swap(jobs_);
    sinks.swap(sinks_);
  }
  for (StepJob& job : jobs) {
    if (job.done) job.done({false, "session " + id_ + " was closed", {}});
  }
  for (const auto& w : sinks) {
    if (const auto s = w.lock()) s->on_session_closed();
  }
  wake_renderer_();
}

std::optional<StepJob> Session::pop_job() {
  std::lock_guard lock(mutex_);
  if (jobs_.empty()) return std::nullopt;
  StepJob job = std::move(jobs_.front());
  jobs_.pop_front();
  return job;
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

}  // namespace downpour::session
