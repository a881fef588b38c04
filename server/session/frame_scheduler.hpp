// The render loop: one thread that owns the GL context. Which session ticks next is TickPolicy's
// call (earliest deadline first); the loop applies the session's inputs, starts its simulation
// step on the step thread, renders each view (the water's passes wait for the step), queues the
// readbacks and hands finished pixels to the encoder workers, which publish the frames. Rendering
// frame N+1 overlaps encoding frame N; a lockstep session's next step, when already queued, runs
// while frame N is read back; the render thread never waits for an encoder.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <functional>
#include <future>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "server/encode/encoder_pool.hpp"
#include "server/render/readback_queue.hpp"
#include "server/render/renderer.hpp"
#include "server/render/warm_up.hpp"
#include "server/session/session_registry.hpp"
#include "server/session/tick_policy.hpp"
#include "server/sim/worker_thread.hpp"

namespace downpour::session {

// Told of every view as it is rendered and as it is encoded (the server's metrics). Called on the
// render thread and on the encoder threads: it must be cheap and thread-safe.
class FrameObserver {
 public:
  virtual ~FrameObserver() = default;
  virtual void rendered(double render_ms) = 0;
  // latency_ms: from the tick that consumed the inputs to the encoded frame (FrameStats).
  virtual void encoded(double encode_ms, double latency_ms) = 0;
};

struct SchedulerOptions {
  render::RendererOptions renderer;
  int encoder_threads = 1;
  bool profile_passes = false;                     // glFinish after each pass (benchmarks)
  std::shared_ptr<FrameObserver> observer;         // may be null
  render::WarmUp warm_up = render::WarmUp::kFull;  // drawn before the loop serves (warm_up.hpp)
  // The step's helper thread (the world outside the glass steps on it beside the glass's water);
  // never on a machine with one core. The benchmark measures the demo without it too.
  bool step_helper = true;
};

struct SchedulerStats {
  std::string renderer;
  std::uint64_t frames_rendered = 0;
  std::uint64_t frames_encoded = 0;
  std::uint64_t realtime_frames_late = 0;  // every session's frame slots missed, together
  double render_ms_median = 0.0;
  double encode_ms_median = 0.0;
  int encoder_threads = 0;
};

class FrameScheduler {
 public:
  FrameScheduler(SessionRegistry& registry, SchedulerOptions options);
  ~FrameScheduler();

  // Starts the render thread, makes the GL context and renders a first (warm-up) frame. Throws
  // with the reason if that fails.
  void start();
  void stop();
  void wake();

  SchedulerStats stats() const;
  // Seconds since the render loop last came round (0 before it starts): a watchdog's input.
  double stalled_s(Clock::time_point now) const;
  // Pass timings of the last rendered view (with profile_passes on).
  std::vector<render::PassTiming> last_pass_timings() const;

 private:
  struct InFlight;
  struct TickCollector;

  void run(std::promise<void>* started);
  // Brings the policy and the renderer's per-session resources in line with the registry.
  void sync_sessions(Clock::time_point now);
  // A step running on the step thread: the frame's inputs (the state after the step but for the
  // water), and what the step threw, if it did.
  struct StartedStep {
    sim::SceneState inputs;
    std::shared_ptr<std::exception_ptr> failure;
  };

  // Throws when the session's frame fails (it is then closed); its step is failed, its encoder
  // room given back.
  void run_tick(const TickPolicy::Tick& tick);
  // A lockstep session's next step job, the updates queued before it applied; none if no step
  // waits.
  std::optional<StepJob> pop_step(Session& s);
  static std::unique_ptr<sim::WorkerThread> make_world_worker(bool wanted);
  StartedStep start_step(Session& s, double dt_s);
  void tick(const std::shared_ptr<Session>& s, const StartedStep& step, StepDone done,
            Clock::time_point inputs_arrived);
  // Fails the step started ahead (its session closed, the server stopping).
  void drop_step_ahead(EndReason reason, const std::string& why);
  void collect(bool all);
  void loop_once(Clock::time_point now);  // one turn of the render loop
  void encode(InFlight f, std::vector<std::uint8_t> pixels, render::GroundTruthPixels truth,
              double readback_ms);
  void record(std::vector<double>& window, std::size_t& next, double value);

  SessionRegistry& registry_;
  const SchedulerOptions options_;
  // Render thread only:
  std::unique_ptr<render::Renderer> renderer_;
  std::unique_ptr<render::ReadbackQueue<InFlight>> readbacks_;
  std::map<std::uint64_t, std::shared_ptr<Session>> live_;  // by number
  std::map<std::uint64_t, std::unique_ptr<render::RenderSession>> render_sessions_;
  TickPolicy policy_;
  // A lockstep session's next step, started as soon as its last tick was drawn when it was
  // already queued: it runs while that tick's frames are read back and encoded.
  struct StepAhead {
    std::shared_ptr<Session> session;
    StepJob job;
    StartedStep step;
  };
  std::optional<StepAhead> ahead_;
  Clock::time_point stats_published_;
  // The step's helper: the world outside the glass steps on it beside the glass's water (none
  // where the server may run on one core only). Declared before the step thread, so that it
  // outlives the step thread's last job.
  std::unique_ptr<sim::WorkerThread> world_worker_;
  sim::WorkerThread step_worker_{"dp-step"};
  std::thread thread_;

  std::mutex wake_mutex_;
  std::condition_variable wake_cv_;
  bool woken_ = false;  // guarded by wake_mutex_
  std::atomic<bool> stopping_{false};
  std::atomic<Clock::rep> heartbeat_{0};  // when the render loop last came round

  mutable std::mutex stats_mutex_;
  std::string renderer_name_;                     // guarded by stats_mutex_
  std::vector<double> render_ms_window_;          // guarded by stats_mutex_
  std::size_t render_ms_next_ = 0;                // guarded by stats_mutex_
  std::vector<double> encode_ms_window_;          // guarded by stats_mutex_
  std::size_t encode_ms_next_ = 0;                // guarded by stats_mutex_
  std::vector<render::PassTiming> pass_timings_;  // guarded by stats_mutex_
  std::atomic<std::uint64_t> frames_rendered_{0};
  std::atomic<std::uint64_t> frames_encoded_{0};
  std::atomic<std::uint64_t> frames_late_{0};
  std::uint64_t frames_late_closed_ = 0;  // render thread only
  // Last, so that it is destroyed first: its workers finish their jobs, which use the members
  // above.
  encode::EncoderPool encoders_;
};

}  // namespace downpour::session
