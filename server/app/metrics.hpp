// Prometheus metrics (--metrics-listen): an HTTP endpoint, /metrics, in the text format. Frames
// and calls are counted as they happen (a FrameObserver, a call-status callback); the rest is
// sampled from the server's state by the main loop (update).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include <grpcpp/support/status.h>

#include "server/session/frame_scheduler.hpp"

namespace downpour::app {

// What the main loop samples four times a second.
struct MetricsSample {
  std::uint64_t frames_dropped = 0;  // readers' missed frames, since start
  std::uint64_t frames_late = 0;     // realtime frame slots missed, since start
  std::uint64_t sessions_closed_idle = 0;
  int sessions_lockstep = 0;
  int sessions_realtime = 0;
  int steps_in_flight = 0;
  int open_streams = 0;
  double pixel_rate_mpx_s = 0.0;
  double memory_estimate_mib = 0.0;
  bool serving = false;
  double render_loop_stalled_s = 0.0;
};

class Metrics final : public session::FrameObserver {
 public:
  // Serves /metrics on `listen` (host:port; port 0 picks a free one). Throws std::runtime_error
  // if it cannot listen there.
  explicit Metrics(const std::string& listen);
  ~Metrics() override;
  Metrics(const Metrics&) = delete;
  Metrics& operator=(const Metrics&) = delete;

  int port() const;

  void rendered(double render_ms) override;
  void encoded(double encode_ms, double latency_ms) override;
  // A call ended with `code` (rpc/call_status.hpp).
  void call_finished(std::string_view method, grpc::StatusCode code);
  void update(const MetricsSample& sample);
  // downpour_build_info{version, renderer} 1, once the renderer is known.
  void set_build_info(const std::string& version, const std::string& renderer);

  // The registry's families in the text format, as /metrics serves them (tests).
  std::string text() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The name of a status code as Prometheus labels and gRPC's docs spell it ("NOT_FOUND").
std::string_view status_code_name(grpc::StatusCode code);

}  // namespace downpour::app
