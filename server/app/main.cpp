// downpour-server: wiring. Parses the configuration, starts the render loop (which makes the GL
// context and renders a first frame), then serves gRPC until SIGINT or SIGTERM, and drains.
#include <csignal>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <string>

#include <grpcpp/ext/proto_server_reflection_plugin.h>
#include <grpcpp/grpcpp.h>
#include <grpcpp/health_check_service_interface.h>
#include <spdlog/spdlog.h>

#include "server/app/server_config.hpp"
#include "server/rpc/downpour_service.hpp"
#include "server/session/frame_scheduler.hpp"
#include "server/session/session_registry.hpp"

int main(int argc, char** argv) {
  using namespace downpour;
  int exit_code = 0;
  const auto config = app::parse_config(argc, argv, &exit_code);
  if (!config) return exit_code;
  spdlog::set_level(spdlog::level::from_str(config->log_level));
  if (config->render_threads > 0)
    setenv("LP_NUM_THREADS", std::to_string(config->render_threads).c_str(), 1);

  // Signals go to sigwait below, not to whichever thread happens to run.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);

  session::FrameScheduler* scheduler_ptr = nullptr;
  session::SessionRegistry registry(config->max_sessions, [&scheduler_ptr] {
    if (scheduler_ptr) scheduler_ptr->wake();
  });
  session::SchedulerOptions options;
  options.renderer.platform = config->renderer;
  options.encoder_threads = config->encoder_threads;
  session::FrameScheduler scheduler(registry, options);
  try {
    scheduler.start();
  } catch (const std::exception& e) {
    spdlog::critical("cannot render: {}", e.what());
    return 1;
  }
  scheduler_ptr = &scheduler;
  spdlog::info("renderer: {}", scheduler.stats().renderer);

  rpc::Limits limits;
  limits.max_width = config->max_width;
  limits.max_height = config->max_height;
  limits.max_fps = config->max_fps;
  rpc::DownpourService service(registry, scheduler, limits);

  grpc::EnableDefaultHealthCheckService(true);
  grpc::reflection::InitProtoReflectionServerBuilderPlugin();
  grpc::ServerBuilder builder;
  int port = 0;
  builder.AddListeningPort(config->listen, grpc::InsecureServerCredentials(), &port);
  builder.RegisterService(&service);
  builder.SetMaxReceiveMessageSize(1 << 20);
  std::unique_ptr<grpc::Server> server = builder.BuildAndStart();
  if (!server || port == 0) {
    spdlog::critical("cannot listen on {}", config->listen);
    return 1;
  }
  // The GL context exists and a first frame rendered (scheduler.start): report SERVING.
  server->GetHealthCheckService()->SetServingStatus(true);
  spdlog::info("listening on {} (port {}), up to {} sessions", config->listen, port,
               config->max_sessions);
  if (!config->port_file.empty()) {
    const std::string tmp = config->port_file + ".tmp";
    std::ofstream(tmp) << port << "\n";
    std::rename(tmp.c_str(), config->port_file.c_str());
  }

  timespec wait{
      static_cast<time_t>(config->stats_interval_s),
      static_cast<long>((config->stats_interval_s - static_cast<time_t>(config->stats_interval_s)) *
                        1e9)};
  int signal_number = 0;
  for (;;) {
    signal_number = sigtimedwait(&signals, nullptr, &wait);
    if (signal_number > 0) break;
    const session::SchedulerStats s = scheduler.stats();
    spdlog::info(
        "stats: {} sessions, {} frames rendered, {} encoded, render {:.2f} ms, encode {:.2f} ms "
        "(medians)",
        registry.list().size(), s.frames_rendered, s.frames_encoded, s.render_ms_median,
        s.encode_ms_median);
  }
  spdlog::info("signal {}: draining", signal_number);
  server->GetHealthCheckService()->SetServingStatus(false);
  registry
      .close_all();  // ends streams and fails queued steps, so that shutdown does not wait on them
  server->Shutdown(std::chrono::system_clock::now() + std::chrono::seconds(5));
  scheduler.stop();
  spdlog::info("stopped");
  return 0;
}
