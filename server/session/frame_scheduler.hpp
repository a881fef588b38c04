// The render loop: one thread that owns the GL context. It picks the sessions that are due
// (realtime by their frame rate, lockstep by a pending step), applies their inputs, steps their
// simulations, renders each view, starts the readbacks and hands finished pixels to the encoder
// workers, which publish the frames. Rendering frame N+1 overlaps encoding frame N.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <future>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "server/encode/encoder_pool.hpp"
#include "server/render/renderer.hpp"
#include "server/session/session_registry.hpp"

namespace downpour::session {

struct SchedulerOptions {
  render::RendererOptions renderer;
  int encoder_threads = 1;
  bool profile_passes = false;  // glFinish after each pass (benchmarks)
};

struct SchedulerStats {
  std::string renderer;
  std::uint64_t frames_rendered = 0;
  std::uint64_t frames_encoded = 0;
  std::uint64_t realtime_ticks_skipped = 0;  // encoders busy when a realtime tick was due
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
  // Pass timings of the last rendered view (with profile_passes on).
  std::vector<render::PassTiming> last_pass_timings() const;

 private:
  struct InFlight;
  struct TickCollector;

  void run(std::promise<void>* started);
  bool run_lockstep(const std::shared_ptr<Session>& s);
  bool run_realtime(const std::shared_ptr<Session>& s, Clock::time_point now);
  void tick(const std::shared_ptr<Session>& s, double dt_s, StepDone done,
            Clock::time_point inputs_arrived);
  void collect(bool force_all);
  void release_closed_sessions(const std::vector<std::shared_ptr<Session>>& live);
  void record(std::vector<double>& window, std::size_t& next, double value);

  SessionRegistry& registry_;
  const SchedulerOptions options_;
  std::unique_ptr<render::Renderer> renderer_;  // render thread only
  std::vector<InFlight> in_flight_;             // render thread only
  std::vector<std::uint64_t> known_sessions_;   // render thread only
  std::thread thread_;

  std::mutex wake_mutex_;
  std::condition_variable wake_cv_;
  bool woken_ = false;  // guarded by wake_mutex_
  std::atomic<bool> stopping_{false};

  mutable std::mutex stats_mutex_;
  std::string renderer_name_;                     // guarded by stats_mutex_
  std::vector<double> render_ms_window_;          // guarded by stats_mutex_
  std::size_t render_ms_next_ = 0;                // guarded by stats_mutex_
  std::vector<double> encode_ms_window_;          // guarded by stats_mutex_
  std::size_t encode_ms_next_ = 0;                // guarded by stats_mutex_
  std::vector<render::PassTiming> pass_timings_;  // guarded by stats_mutex_
  std::atomic<std::uint64_t> frames_rendered_{0};
  std::atomic<std::uint64_t> frames_encoded_{0};
  std::atomic<std::uint64_t> ticks_skipped_{0};
  // Last, so that it is destroyed first: its workers finish their jobs, which use the members
  // above.
  encode::EncoderPool encoders_;
};

}  // namespace downpour::session
