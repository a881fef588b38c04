// One simulator's world: its configuration, the inbox of inputs from gRPC threads, the
// simulation (render thread only) and the readers of its frames.
#pragma once

#include <array>
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
#include "server/session/tick_policy.hpp"
#include "server/sim/simulation.hpp"
#include "server/sim/types.hpp"
#include "server/sim/windshield.hpp"

namespace downpour::session {

struct SessionConfig {
  std::vector<sim::ViewSpec> views;
  sim::Mode mode = sim::Mode::kRealtime;
  double fps = 30.0;
  std::uint64_t seed = 0;
  std::string owner;  // the principal that created it (rpc/auth.hpp); it alone drives it
  // Its roads (sim/road_network.hpp): null, the built-in track; and what the client named them.
  std::shared_ptr<const sim::RoadNetwork> roads;
  std::string road_network = "built-in track";
  sim::EgoGeometry ego;
  sim::GlassConfig glass;  // the windshield the water runs on
};

struct StepOutcome {
  bool ok = false;
  std::string error;                       // when !ok
  EndReason failure = EndReason::kFailed;  // when !ok: why
  std::vector<FramePtr> frames;            // one per view, in the session's view order
};
using StepDone = std::function<void(StepOutcome)>;

// Set when the call that asked for a step is cancelled (or its deadline passes).
using CancelFlag = std::shared_ptr<const std::atomic<bool>>;

// A lockstep request: apply the update, then (dt_s > 0) advance and render; done gets the frames.
struct StepJob {
  sim::Update update;
  double dt_s = 0.0;
  StepDone done;  // empty for update-only jobs
  Clock::time_point arrived;
  CancelFlag cancelled;  // may be null
  bool is_cancelled() const { return cancelled && cancelled->load(); }
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
  // already waiting, so that a feed's order is kept (folded into an update already waiting at the
  // queue's end: updates alone never fill it).
  enum class Submit { kQueued, kFull, kClosed };
  Submit post_update(const sim::Update& update);
  // A step whose call is cancelled before the step starts is dropped, update and all (its done
  // gets kCancelled), and no longer counts against the queue's bound.
  Submit submit_step(sim::Update update, double dt_s, StepDone done, CancelFlag cancelled = {});
  void add_sink(const std::shared_ptr<FrameSink>& sink);
  void remove_sink(const FrameSink* sink);
  // Fails the steps still queued, ends the readers' streams, both with the reason. Idempotent:
  // the first reason stays.
  void close(const SessionEnd& end = {});
  bool closed() const { return closed_.load(); }
  std::uint64_t frames_rendered() const { return frames_rendered_.load(); }
  double sim_time_s() const { return sim_time_s_.load(); }
  // How the session keeps its rate, as the render loop last reported it.
  TickStats tick_stats() const;
  // A client was heard: a request for the session (its lease runs from here).
  void touch();
  // A Drive stream is attached: while one is, the session is not idle.
  void attach_stream();
  void detach_stream();
  // Seconds since a client was last heard; 0 while a stream is attached.
  double idle_s(Clock::time_point now) const;

  // --- render thread ---
  // When the oldest step (a job with dt_s > 0) waiting arrived, if one waits.
  std::optional<Clock::time_point> oldest_step_arrival() const;
  std::optional<StepJob> pop_job();  // skips (and fails) cancelled steps
  // Answers and forgets the queued steps whose calls were cancelled, so that they neither hold
  // the queue nor count as in flight; the scheduler calls it for every live session each pass.
  void drop_cancelled();
  // The realtime inbox: the folded update and when its newest part arrived.
  std::optional<std::pair<sim::Update, Clock::time_point>> take_update();
  sim::Simulation& simulation() { return simulation_; }
  std::uint64_t begin_frame();  // the next frame number; counts the frame
  void note_sim_time() { sim_time_s_.store(simulation_.state().sim_time_s); }
  void set_tick_stats(const TickStats& stats);
  std::uint64_t steps_cancelled() const { return steps_cancelled_.load(); }
  // A client-background view drawn over `image` (null: none yet): its repeats so far, this one
  // counted where the picture is not new to it.
  std::uint64_t note_background(sim::View view, const sim::ClientImage* image);

  // --- encoder threads ---
  void publish(const FramePtr& frame);

 private:
  const std::string id_;
  const std::uint64_t number_;
  const SessionConfig config_;
  const std::function<void()> wake_renderer_;
  sim::Simulation simulation_;    // render thread only
  std::uint64_t next_frame_ = 1;  // render thread only
  // Each view's last picture drawn (its serial) and its repeats: render thread only.
  std::array<std::uint64_t, sim::kViewCount> background_drawn_{};
  std::array<std::uint64_t, sim::kViewCount> background_repeats_{};

  mutable std::mutex mutex_;
  std::deque<StepJob> jobs_;                     // guarded by mutex_
  std::optional<sim::Update> inbox_;             // guarded by mutex_
  Clock::time_point inbox_arrived_;              // guarded by mutex_
  std::vector<std::weak_ptr<FrameSink>> sinks_;  // guarded by mutex_
  SessionEnd end_;                               // guarded by mutex_: set by close()
  TickStats tick_stats_;                         // guarded by mutex_
  std::atomic<bool> closed_{false};
  std::atomic<std::uint64_t> frames_rendered_{0};
  std::atomic<double> sim_time_s_{0.0};
  std::atomic<Clock::rep> last_heard_;  // Clock ticks since its epoch
  std::atomic<int> streams_{0};
  std::atomic<std::uint64_t> steps_cancelled_{0};

  // Moves the cancelled steps out of jobs_ (mutex_ held); fail_cancelled() answers them after.
  void take_cancelled(std::vector<StepJob>* out);
  void fail_cancelled(std::vector<StepJob> jobs);
};

}  // namespace downpour::session
