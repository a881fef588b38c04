// downpour-server: wiring. Parses the configuration, starts the render loop (which makes the GL
// context and renders a first frame), then serves gRPC until SIGINT or SIGTERM, and drains.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <string>
#include <thread>

#include <grpcpp/ext/proto_server_reflection_plugin.h>
#include <grpcpp/grpcpp.h>
#include <grpcpp/health_check_service_interface.h>
#include <spdlog/spdlog.h>

#include "grpc_health/v1/health.pb.h"
#include "server/app/fatal_signals.hpp"
#include "server/app/log_format.hpp"
#include "server/app/metrics.hpp"
#include "server/app/server_config.hpp"
#include "server/render/gl/egl_context.hpp"
#include "server/rpc/call_status.hpp"
#include "server/rpc/downpour_service.hpp"
#include "server/rpc/malformed_request.hpp"
#include "server/session/frame_scheduler.hpp"
#include "server/session/session_registry.hpp"

namespace downpour::app {
namespace {

// SIGINT and SIGTERM are blocked in every thread of ours and taken with sigtimedwait. A thread
// that is not ours and does not block them (ThreadSanitizer's own, started before main) can still
// receive one: with no handler, that would end the process on the spot instead of draining. The
// handler keeps the signal for the main loop to take.
std::atomic<int> g_caught_signal{0};
static_assert(std::atomic<int>::is_always_lock_free, "touched from a signal handler");

extern "C" void keep_signal(int number) { g_caught_signal.store(number); }

// The next SIGINT or SIGTERM within `wait`, 0 if none came.
int next_signal(const sigset_t& signals, const timespec& wait) {
  const int number = sigtimedwait(&signals, nullptr, &wait);
  if (number > 0) return number;
  return g_caught_signal.exchange(0);
}

// The server's state, into the metrics.
void sample_metrics(Metrics& metrics, session::SessionRegistry& registry,
                    const rpc::DownpourService& service, const session::FrameScheduler& scheduler,
                    bool serving, double stalled_s) {
  MetricsSample s;
  for (const auto& session : registry.list()) {
    if (session->config().mode == sim::Mode::kLockstep) {
      ++s.sessions_lockstep;
    } else {
      ++s.sessions_realtime;
    }
  }
  s.frames_dropped = service.frames_dropped();
  s.frames_late = scheduler.stats().realtime_frames_late;
  s.sessions_closed_idle = registry.closed_idle();
  s.steps_in_flight = service.steps_in_flight();
  s.open_streams = service.open_streams();
  const session::SessionCost used = registry.cost_in_use();
  s.pixel_rate_mpx_s = used.pixel_rate / 1e6;
  s.memory_estimate_mib = used.memory_bytes / (1024.0 * 1024.0);
  s.serving = serving;
  s.render_loop_stalled_s = stalled_s;
  metrics.update(s);
}

// The log's level and format as configured, and the first line.
void set_up_logging(const ServerConfig& config) {
  spdlog::set_level(spdlog::level::from_str(config.log_level));
  set_log_format(config.log_format);
  spdlog::info("downpour-server {}", kVersion);
}

// Security first: a server that would be exposed, or whose keys or tokens cannot be read, does
// not start (false, logged). Else the tokens and the main port's credentials.
bool load_security(const ServerConfig& config, rpc::Authenticator& auth,
                   std::shared_ptr<grpc::ServerCredentials>& credentials) {
  if (const std::string problem = security_problem(config); !problem.empty()) {
    spdlog::critical("{}", problem);
    return false;
  }
  try {
    if (!config.tokens_file.empty()) auth = rpc::Authenticator::from_file(config.tokens_file);
    credentials = server_credentials(config);
  } catch (const std::exception& e) {
    spdlog::critical("{}", e.what());
    return false;
  }
  return true;
}

// Signals go to next_signal (sigtimedwait), not to whichever thread happens to run: blocked here,
// before any thread is started (they inherit the mask), with keep_signal as the handler. The set.
sigset_t block_signals() {
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  struct sigaction keep {};
  keep.sa_handler = keep_signal;
  sigemptyset(&keep.sa_mask);
  sigaction(SIGINT, &keep, nullptr);
  sigaction(SIGTERM, &keep, nullptr);
  return signals;
}

// The metrics endpoint if --metrics-listen names one (else none); false (logged) where its port
// cannot be had.
bool open_metrics(const ServerConfig& config, std::shared_ptr<Metrics>& metrics) {
  if (config.metrics_listen.empty()) return true;
  try {
    metrics = std::make_shared<Metrics>(config.metrics_listen);
  } catch (const std::exception& e) {
    spdlog::critical("{} (--metrics-listen)", e.what());
    return false;
  }
  spdlog::info("metrics on http://{}/metrics (port {})", config.metrics_listen, metrics->port());
  if (!rpc::loopback_only(config.metrics_listen)) {
    spdlog::warn(
        "metrics listen beyond loopback ({}), without TLS or tokens: keep that network "
        "private",
        config.metrics_listen);
  }
  return true;
}

// The render loop's options: its renderer and encoders as configured, the metrics (if any) watching
// its frames.
session::SchedulerOptions scheduler_options(const ServerConfig& config,
                                            std::shared_ptr<Metrics> metrics) {
  session::SchedulerOptions options;
  options.observer = std::move(metrics);
  options.renderer.platform = config.renderer;
  options.renderer.spray_smoothing = config.spray_smoothing;
  options.warm_up = config.warm_up;
  options.encoder_threads = config.encoder_threads;
  return options;
}

// Starts the render loop (the EGL context and a first frame); false (logged) where it cannot.
bool start_render_loop(session::FrameScheduler& scheduler) {
  try {
    scheduler.start();
  } catch (const std::exception& e) {
    spdlog::critical("cannot render: {}", e.what());
    return false;
  }
  return true;
}

// The admission budgets sized for the renderer the render loop found.
void admit_for_renderer(const ServerConfig& config, const session::FrameScheduler& scheduler,
                        session::SessionRegistry& registry, Metrics* metrics) {
  const std::string renderer = scheduler.stats().renderer;
  spdlog::info("renderer: {}", renderer);
  if (metrics) metrics->set_build_info(kVersion, renderer);
  const session::AdmissionBudget budget = admission_budget(config, renderer);
  registry.set_budget(budget);
  spdlog::info("admission: {:.0f} Mpx/s, {:.0f} MiB of estimated session memory (0 = no limit)",
               budget.max_pixel_rate / 1e6, budget.max_memory_bytes / (1024.0 * 1024.0));
}

// How far past --max-message-mb gRPC still reads a request (for the service to refuse it clearly).
constexpr int kRequestSlackMb = 16;

// What a request may ask for.
rpc::Limits request_limits(const ServerConfig& config) {
  rpc::Limits limits;
  limits.max_width = config.max_width;
  limits.max_height = config.max_height;
  limits.max_fps = config.max_fps;
  limits.max_request_bytes = static_cast<std::size_t>(config.max_message_mb) << 20;
  return limits;
}

// The road networks sessions may name (from --maps-dir) or send.
std::shared_ptr<rpc::RoadNetworks> road_networks(const ServerConfig& config) {
  road::Limits road_limits;
  road_limits.max_total_length_m = config.max_road_km * 1000.0;
  auto networks = std::make_shared<rpc::RoadNetworks>(config.maps_dir, road_limits);
  if (!config.maps_dir.empty()) spdlog::info("maps from {}", config.maps_dir);
  return networks;
}

// The vehicle and cabin models sessions may name (from --models-dir).
std::shared_ptr<model::ModelLibrary> model_library(const ServerConfig& config) {
  model::ModelLimits limits;
  limits.max_bytes = static_cast<std::size_t>(config.model_max_mb) << 20;
  limits.max_triangles = static_cast<std::size_t>(config.model_max_triangles);
  if (!config.models_dir.empty()) spdlog::info("models from {}", config.models_dir);
  return std::make_shared<model::ModelLibrary>(config.models_dir, limits);
}

// Probes that cannot speak TLS get the health service alone, in plaintext, on its own port
// (--health-listen; none if empty). Built before reflection is enabled (a process-wide plugin),
// so it offers nothing else. False (logged) where the port cannot be had.
bool start_health_server(const ServerConfig& config, std::unique_ptr<grpc::Server>& health_server) {
  if (config.health_listen.empty()) return true;
  grpc::ServerBuilder health_builder;
  int health_port = 0;
  health_builder.AddListeningPort(config.health_listen, grpc::InsecureServerCredentials(),
                                  &health_port);
  health_server = health_builder.BuildAndStart();
  if (!health_server || health_port == 0) {
    spdlog::critical("cannot listen on {} (--health-listen)", config.health_listen);
    return false;
  }
  health_server->GetHealthCheckService()->SetServingStatus(false);  // until the main port is up
  spdlog::info("health alone on {} (port {})", config.health_listen, health_port);
  return true;
}

// The gRPC server on --listen, serving `service` (and reflection); its port in `port`. None
// (logged) where it cannot listen.
std::unique_ptr<grpc::Server> start_server(
    const ServerConfig& config, const std::shared_ptr<grpc::ServerCredentials>& credentials,
    rpc::DownpourService& service, const std::shared_ptr<Metrics>& metrics, int& port) {
  // Reflection describes the public schema (proto/) to tools such as grpcurl; the calls it
  // describes still need their tokens. gRPC's built-in health service carries no descriptor of
  // its own (grpc/grpc#36665): naming our copy of health.proto's here links it into the binary,
  // and so into the pool reflection reads.
  grpc::health::v1::HealthCheckRequest::descriptor();
  grpc::reflection::InitProtoReflectionServerBuilderPlugin();
  grpc::ServerBuilder builder;
  builder.AddListeningPort(config.listen, credentials, &port);
  builder.RegisterService(&service);
  // gRPC takes a request somewhat past --max-message-mb, so that the service can refuse it with a
  // status that names the flag (rpc::check_request_size); gRPC's own refusal past this says only
  // the sizes.
  builder.SetMaxReceiveMessageSize((config.max_message_mb + kRequestSlackMb) << 20);
  auto interceptors = rpc::malformed_request_interceptors();
  if (metrics) {  // after malformed_request's, so that it counts the status that goes out
    interceptors.push_back(
        rpc::call_status_interceptor([metrics](std::string_view method, grpc::StatusCode code) {
          metrics->call_finished(method, code);
        }));
  }
  builder.experimental().SetInterceptorCreators(std::move(interceptors));
  // Pings find a client whose host died with a stream open (no FIN ever comes): after 20 s of
  // silence a ping, and 10 s without its answer closes the connection, so the stream's lease on
  // its session ends and the idle timeout can take it.
  builder.AddChannelArgument(GRPC_ARG_KEEPALIVE_TIME_MS, 20000);
  builder.AddChannelArgument(GRPC_ARG_KEEPALIVE_TIMEOUT_MS, 10000);
  builder.AddChannelArgument(GRPC_ARG_HTTP2_MAX_PINGS_WITHOUT_DATA, 0);  // a quiet stream too
  std::unique_ptr<grpc::Server> server = builder.BuildAndStart();
  if (!server || port == 0) {
    spdlog::critical("cannot listen on {}", config.listen);
    return nullptr;
  }
  return server;
}

// The server is up: its security and address to the log, its port to --port-file if given.
void report_serving(const ServerConfig& config, const rpc::Authenticator& auth, int port) {
  spdlog::info("security: {}, {}",
               config.tls_cert.empty()        ? "plaintext"
               : config.tls_client_ca.empty() ? "TLS"
                                              : "mutual TLS",
               auth.requires_tokens() ? std::to_string(auth.token_count()) + " tokens"
                                      : std::string("no tokens (every client may do everything)"));
  spdlog::info("listening on {} (port {}), up to {} sessions", config.listen, port,
               config.max_sessions);
  if (!config.port_file.empty()) {
    const std::string tmp = config.port_file + ".tmp";
    std::ofstream(tmp) << port << "\n";
    std::rename(tmp.c_str(), config.port_file.c_str());
  }
}

// What the serving loop and the drain act on.
struct Running {
  const ServerConfig& config;
  session::SessionRegistry& registry;
  session::FrameScheduler& scheduler;
  rpc::DownpourService& service;
  grpc::Server& server;
  grpc::Server* health_server;  // the health-only server, if any

  // Health on both ports.
  void set_serving(bool serving) const {
    server.GetHealthCheckService()->SetServingStatus(serving);
    if (health_server) health_server->GetHealthCheckService()->SetServingStatus(serving);
  }
};

using Clock = std::chrono::steady_clock;

// Serve until a signal; its number. Four times a second the watchdog looks at the render loop: one
// that has not come round for --watchdog-s turns health NOT_SERVING (a balancer stops sending work)
// until it does again. Every --stats-interval a stats line goes to the log.
int serve_until_signal(const Running& run, const sigset_t& signals, Metrics* metrics) {
  const ServerConfig& config = run.config;
  const auto stats_every = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(config.stats_interval_s));
  Clock::time_point next_stats = Clock::now() + stats_every;
  const timespec quarter{0, 250'000'000};
  bool serving = true;
  for (;;) {
    const int signal_number = next_signal(signals, quarter);
    if (signal_number > 0) return signal_number;
    const Clock::time_point now = Clock::now();
    const double stalled = run.scheduler.stalled_s(now);
    const bool healthy = config.watchdog_s <= 0.0 || stalled < config.watchdog_s;
    if (metrics)
      sample_metrics(*metrics, run.registry, run.service, run.scheduler, serving, stalled);
    if (healthy != serving) {
      serving = healthy;
      run.set_serving(serving);
      if (serving) {
        spdlog::warn("watchdog: the render loop came round again; SERVING");
      } else {
        spdlog::error("watchdog: the render loop has not come round for {:.1f} s; NOT_SERVING",
                      stalled);
      }
    }
    if (now < next_stats) continue;
    next_stats = now + stats_every;
    const session::SchedulerStats s = run.scheduler.stats();
    spdlog::info(
        "stats: {} sessions, {} frames rendered, {} encoded, render {:.2f} ms, encode {:.2f} ms "
        "(medians)",
        run.registry.list().size(), s.frames_rendered, s.frames_encoded, s.render_ms_median,
        s.encode_ms_median);
  }
}

// Drain: refuse new work, answer the steps already accepted, end every stream with UNAVAILABLE,
// and be gone within the grace (a second signal skips the wait for steps).
void drain(const Running& run, const sigset_t& signals, int signal_number) {
  const ServerConfig& config = run.config;
  rpc::DownpourService& service = run.service;
  const Clock::time_point drain_start = Clock::now();
  const Clock::time_point deadline =
      drain_start + std::chrono::duration_cast<Clock::duration>(
                        std::chrono::duration<double>(config.shutdown_grace_s));
  // What the steps leave of the grace for ending the streams and stopping the render loop.
  const auto reserve = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(std::min(2.0, config.shutdown_grace_s * 0.25)));
  spdlog::info("signal {}: draining ({} steps in flight; grace {:.0f} s)", signal_number,
               service.steps_in_flight(), config.shutdown_grace_s);
  // A render loop stuck in the driver cannot stop: past the grace (and a second to log) the
  // process ends anyway, so that an orchestrator's SIGKILL is never what ends it.
  std::thread([deadline] {
    std::this_thread::sleep_until(deadline + std::chrono::seconds(1));
    spdlog::critical("the drain outlived its grace; exiting now");
    spdlog::default_logger()->flush();
    std::_Exit(2);
  }).detach();
  service.begin_drain();  // before health says so: a client that sees NOT_SERVING is refused
  run.set_serving(false);
  const timespec poll{0, 10'000'000};
  while (service.steps_in_flight() > 0 && Clock::now() < deadline - reserve) {
    if (next_signal(signals, poll) > 0) {
      spdlog::warn("second signal: not waiting for the {} steps in flight",
                   service.steps_in_flight());
      break;
    }
  }
  if (const int left = service.steps_in_flight(); left > 0)
    spdlog::warn("{} steps were still in flight at the end of the grace", left);
  run.registry.close_all({session::EndReason::kShuttingDown, "server shutting down"});
  // The streams send their status; one whose reader has stalled cannot, and is cancelled.
  const Clock::time_point flushed =
      std::min(Clock::now() + std::chrono::milliseconds(500), deadline);
  while (service.open_streams() > 0 && Clock::now() < flushed) next_signal(signals, poll);
  run.server.Shutdown(std::chrono::system_clock::now());  // cancels what is left
  if (run.health_server) run.health_server->Shutdown(std::chrono::system_clock::now());
  run.scheduler.stop();
  spdlog::info("stopped after {:.2f} s of drain",
               std::chrono::duration<double>(Clock::now() - drain_start).count());
}

}  // namespace
}  // namespace downpour::app

int main(int argc, char** argv) {
  using namespace downpour;
  int exit_code = 0;
  const auto config = app::parse_config(argc, argv, &exit_code);
  if (!config) return exit_code;
  // It sets the environment: before anything that may start a thread (gRPC's credentials).
  render::choose_rasterizer_threads(config->render_threads);
  app::set_up_logging(*config);
  app::report_fatal_signals();
  rpc::Authenticator auth;
  std::shared_ptr<grpc::ServerCredentials> credentials;
  if (!app::load_security(*config, auth, credentials)) return 2;
  const sigset_t signals = app::block_signals();

  session::FrameScheduler* scheduler_ptr = nullptr;
  session::SessionRegistry registry(config->max_sessions, [&scheduler_ptr] {
    if (scheduler_ptr) scheduler_ptr->wake();
  });
  registry.set_idle_timeout_s(config->session_idle_timeout_s);
  // Metrics first: a port that cannot be had stops the server before the GL context is made.
  std::shared_ptr<app::Metrics> metrics;
  if (!app::open_metrics(*config, metrics)) return 1;
  session::FrameScheduler scheduler(registry, app::scheduler_options(*config, metrics));
  if (!app::start_render_loop(scheduler)) return 1;
  scheduler_ptr = &scheduler;
  app::admit_for_renderer(*config, scheduler, registry, metrics.get());

  rpc::DownpourService service(registry, scheduler, app::request_limits(*config), auth,
                               app::road_networks(*config), app::model_library(*config));
  service.set_identity(app::kVersion, config->advertise);
  if (!config->advertise.empty()) spdlog::info("advertising {} to clients", config->advertise);

  grpc::EnableDefaultHealthCheckService(true);
  std::unique_ptr<grpc::Server> health_server;  // before the main server (and its reflection)
  if (!app::start_health_server(*config, health_server)) return 1;
  int port = 0;
  const std::unique_ptr<grpc::Server> server =
      app::start_server(*config, credentials, service, metrics, port);
  if (!server) return 1;
  const app::Running running{*config, registry, scheduler, service, *server, health_server.get()};
  // The GL context exists and a first frame rendered (scheduler.start): report SERVING.
  running.set_serving(true);
  app::report_serving(*config, auth, port);

  const int signal_number = app::serve_until_signal(running, signals, metrics.get());
  app::drain(running, signals, signal_number);
  return 0;
}
