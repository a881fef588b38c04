// One simulator's world: its configuration, the inbox of inputs from gRPC threads, the
// simulation (render thread only) and the readers of its frames.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "server/session/frame.hpp"
#include "server/sim/simulation.hpp"
#include "server/sim/types.hpp"

namespace downpour::session {

using Clock = std::chrono::steady_clock;

struct SessionConfig {
  std::vector<sim::ViewSpec> views;
  sim::Mode mode = sim::Mode::kRealtime;
  double fps = 30.0;
  std::uint64_t seed = 0;
};

struct StepOutcome {
  bool ok = false;
  std::string error;             // when !ok
  std::vector<FramePtr> frames;  // one per view, in the session's view order
};
using StepDone = std::function<void(StepOutcome)>;

// A lockstep request: apply the update, then (dt_s > 0) advance and render; done gets the frames.
struct StepJob {
  sim::Update update;
  double dt_s = 0.0;
  StepDone done;  // empty for update-only jobs
  Clock::time_point arrived;
};

class Session {
 public:
  static constexpr std::size_t kMaxQueuedJobs = 32;

  Session(std::string id, std::uint64_t number, SessionConfig config, const sim::Update& initial,
          std::function<void()> wake_renderer);

  const std::string& id() const { return id_; }
  std::uint64_t number() const { return number_; }
  const SessionConfig& config() const { return config_; }

  // --- gRPC threads ---
  // Realtime: folded into the inbox, applied at the next tick. Lockstep: queued after the steps
  // already waiting, so that a feed's order is kept.
  enum class Submit { kQueued, kFull, kClosed };
  Submit post_update(const sim::Update& update);
  Submit submit_step(sim::Update update, double dt_s, StepDone done);
  void add_sink(const std::shared_ptr<FrameSink>& sink);
  void remove_sink(const FrameSink* sink);
  // Fails the steps still queued, ends the readers' streams. Idempotent.
  void close();
  bool closed() const { return closed_.load(); }
  std::uint64_t frames_rendered() const { return frames_rendered_.load(); }
  double sim_time_s() const { return sim_time_s_.load(); }

  // --- render thread ---
  std::optional<StepJob> pop_job();
  // The realtime inbox: the folded update and when its newest part arrived.
  std::optional<std::pair<sim::Update, Clock::time_point>> take_update();
  sim::Simulation& simulation() { return simulation_; }
  std::uint64_t begin_frame();  // the next frame number; counts the frame
  void note_sim_time() { sim_time_s_.store(simulation_.state().sim_time_s); }
  Clock::time_point next_due;   // realtime: when the next tick is due
  Clock::time_point last_tick;  // realtime: when the last tick ran

  // --- encoder threads ---
  void publish(const FramePtr& frame);

 private:
  const std::string id_;
  const std::uint64_t number_;
  const SessionConfig config_;
  const std::function<void()> wake_renderer_;
  sim::Simulation simulation_;    // render thread only
  std::uint64_t next_frame_ = 1;  // render thread only

  mutable std::mutex mutex_;
  std::deque<StepJob> jobs_;                     // guarded by mutex_
  std::optional<sim::Update> inbox_;             // guarded by mutex_
  Clock::time_point inbox_arrived_;              // guarded by mutex_
  std::vector<std::weak_ptr<FrameSink>> sinks_;  // guarded by mutex_
  std::atomic<bool> closed_{false};
  std::atomic<std::uint64_t> frames_rendered_{0};
  std::atomic<double> sim_time_s_{0.0};
};

}  // namespace downpour::session
