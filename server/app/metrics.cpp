#include "server/app/metrics.hpp"

#include <array>
#include <mutex>
#include <sstream>
#include <stdexcept>

#include <prometheus/counter.h>
#include <prometheus/exposer.h>
#include <prometheus/gauge.h>
#include <prometheus/histogram.h>
#include <prometheus/registry.h>
#include <prometheus/text_serializer.h>

namespace downpour::app {

namespace {

using prometheus::BuildCounter;
using prometheus::BuildGauge;
using prometheus::BuildHistogram;
using prometheus::Counter;
using prometheus::Gauge;
using prometheus::Histogram;

// Seconds: a frame's passes take milliseconds on a GPU and tens of them on llvmpipe; a latency
// includes the queue behind other sessions' frames.
const Histogram::BucketBoundaries kFrameBuckets = {0.001, 0.002, 0.005, 0.01, 0.02, 0.05,
                                                   0.1,   0.2,   0.5,   1.0,  2.0};
const Histogram::BucketBoundaries kLatencyBuckets = {0.005, 0.01, 0.02, 0.05, 0.1, 0.2,
                                                     0.5,   1.0,  2.0,  5.0,  10.0};

// Moves a counter to a total kept elsewhere (a counter only goes up).
void advance(Counter& counter, std::uint64_t total) {
  const double now = static_cast<double>(total);
  if (now > counter.Value()) counter.Increment(now - counter.Value());
}

}  // namespace

std::string_view status_code_name(grpc::StatusCode code) {
  static constexpr std::array<std::string_view, 17> kNames = {"OK",
                                                              "CANCELLED",
                                                              "UNKNOWN",
                                                              "INVALID_ARGUMENT",
                                                              "DEADLINE_EXCEEDED",
                                                              "NOT_FOUND",
                                                              "ALREADY_EXISTS",
                                                              "PERMISSION_DENIED",
                                                              "RESOURCE_EXHAUSTED",
                                                              "FAILED_PRECONDITION",
                                                              "ABORTED",
                                                              "OUT_OF_RANGE",
                                                              "UNIMPLEMENTED",
                                                              "INTERNAL",
                                                              "UNAVAILABLE",
                                                              "DATA_LOSS",
                                                              "UNAUTHENTICATED"};
  const int i = static_cast<int>(code);
  return i >= 0 && i < static_cast<int>(kNames.size()) ? kNames[i] : "UNKNOWN";
}

struct Metrics::Impl {
  std::shared_ptr<prometheus::Registry> registry = std::make_shared<prometheus::Registry>();
  std::unique_ptr<prometheus::Exposer> exposer;

  prometheus::Family<Counter>& frames = BuildCounter()
                                            .Name("downpour_frames_total")
                                            .Help(
                                                "Views rendered, encoded, and dropped by readers "
                                                "that were too slow to take them")
                                            .Register(*registry);
  Counter& rendered = frames.Add({{"stage", "rendered"}});
  Counter& encoded = frames.Add({{"stage", "encoded"}});
  Counter& dropped = frames.Add({{"stage", "dropped"}});
  Counter& late = BuildCounter()
                      .Name("downpour_frames_late_total")
                      .Help("Realtime frame slots that passed without a frame (late ticks)")
                      .Register(*registry)
                      .Add({});
  Counter& closed_idle = BuildCounter()
                             .Name("downpour_sessions_closed_idle_total")
                             .Help("Sessions closed because no client was heard from them")
                             .Register(*registry)
                             .Add({});
  Histogram& render_s = BuildHistogram()
                            .Name("downpour_render_seconds")
                            .Help("Render thread time of one view")
                            .Register(*registry)
                            .Add({}, kFrameBuckets);
  Histogram& encode_s = BuildHistogram()
                            .Name("downpour_encode_seconds")
                            .Help("JPEG encoding time of one view")
                            .Register(*registry)
                            .Add({}, kFrameBuckets);
  Histogram& latency_s = BuildHistogram()
                             .Name("downpour_frame_latency_seconds")
                             .Help("From the tick that took a session's inputs to its encoded view")
                             .Register(*registry)
                             .Add({}, kLatencyBuckets);
  prometheus::Family<Gauge>& sessions =
      BuildGauge().Name("downpour_sessions").Help("Open sessions by mode").Register(*registry);
  Gauge& lockstep = sessions.Add({{"mode", "lockstep"}});
  Gauge& realtime = sessions.Add({{"mode", "realtime"}});
  prometheus::Family<Counter>& calls = BuildCounter()
                                           .Name("downpour_rpc_calls_total")
                                           .Help("Calls ended, by method and status code")
                                           .Register(*registry);
  prometheus::Family<Counter>& errors = BuildCounter()
                                            .Name("downpour_rpc_errors_total")
                                            .Help("Calls that ended with a status other than OK")
                                            .Register(*registry);
  Gauge& steps_in_flight = BuildGauge()
                               .Name("downpour_steps_in_flight")
                               .Help("Lockstep steps accepted and not yet answered")
                               .Register(*registry)
                               .Add({});
  Gauge& open_streams = BuildGauge()
                            .Name("downpour_open_streams")
                            .Help("Drive and WatchFrames streams open")
                            .Register(*registry)
                            .Add({});
  Gauge& pixel_rate = BuildGauge()
                          .Name("downpour_pixel_rate_mpx_per_second")
                          .Help("The open sessions' admitted pixel rate")
                          .Register(*registry)
                          .Add({});
  Gauge& memory = BuildGauge()
                      .Name("downpour_session_memory_estimate_mib")
                      .Help("The open sessions' estimated memory")
                      .Register(*registry)
                      .Add({});
  Gauge& serving = BuildGauge()
                       .Name("downpour_serving")
                       .Help("1 while health reports SERVING, 0 otherwise")
                       .Register(*registry)
                       .Add({});
  Gauge& stalled = BuildGauge()
                       .Name("downpour_render_loop_stalled_seconds")
                       .Help("Seconds since the render loop last came round")
                       .Register(*registry)
                       .Add({});
  prometheus::Family<Gauge>& build = BuildGauge()
                                         .Name("downpour_build_info")
                                         .Help("The server's version and GL renderer (always 1)")
                                         .Register(*registry);
};

Metrics::Metrics(const std::string& listen) : impl_(std::make_unique<Impl>()) {
  try {
    impl_->exposer = std::make_unique<prometheus::Exposer>(listen, 1);
  } catch (const std::exception& e) {
    throw std::runtime_error("cannot serve metrics on " + listen + ": " + e.what());
  }
  impl_->exposer->RegisterCollectable(impl_->registry);
}

Metrics::~Metrics() = default;

int Metrics::port() const {
  const std::vector<int> ports = impl_->exposer->GetListeningPorts();
  return ports.empty() ? 0 : ports.front();
}

void Metrics::rendered(double render_ms) {
  impl_->rendered.Increment();
  impl_->render_s.Observe(render_ms / 1000.0);
}

void Metrics::encoded(double encode_ms, double latency_ms) {
  impl_->encoded.Increment();
  impl_->encode_s.Observe(encode_ms / 1000.0);
  impl_->latency_s.Observe(latency_ms / 1000.0);
}

void Metrics::call_finished(std::string_view method, grpc::StatusCode code) {
  const prometheus::Labels labels{{"method", std::string(method)},
                                  {"code", std::string(status_code_name(code))}};
  impl_->calls.Add(labels).Increment();
  if (code != grpc::StatusCode::OK) impl_->errors.Add(labels).Increment();
}

void Metrics::update(const MetricsSample& s) {
  advance(impl_->dropped, s.frames_dropped);
  advance(impl_->late, s.frames_late);
  advance(impl_->closed_idle, s.sessions_closed_idle);
  impl_->lockstep.Set(s.sessions_lockstep);
  impl_->realtime.Set(s.sessions_realtime);
  impl_->steps_in_flight.Set(s.steps_in_flight);
  impl_->open_streams.Set(s.open_streams);
  impl_->pixel_rate.Set(s.pixel_rate_mpx_s);
  impl_->memory.Set(s.memory_estimate_mib);
  impl_->serving.Set(s.serving ? 1.0 : 0.0);
  impl_->stalled.Set(s.render_loop_stalled_s);
}

void Metrics::set_build_info(const std::string& version, const std::string& renderer) {
  impl_->build.Add({{"version", version}, {"renderer", renderer}}).Set(1.0);
}

std::string Metrics::text() const {
  std::ostringstream out;
  prometheus::TextSerializer().Serialize(out, impl_->registry->Collect());
  return out.str();
}

}  // namespace downpour::app
