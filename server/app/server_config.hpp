// The server's configuration: command-line flags (CLI11), each also settable from an environment
// variable (DOWNPOUR_<FLAG>) for containers.
#pragma once

#include <memory>
#include <optional>
#include <string>

#include <grpcpp/security/server_credentials.h>

#include "server/render/cpu/spray_smoothing.hpp"
#include "server/render/gl/egl_context.hpp"
#include "server/render/warm_up.hpp"
#include "server/session/admission.hpp"

namespace downpour::app {

// The server's version: the CMake project's (--version, GetStats, the metrics' build info).
extern const char* const kVersion;

struct ServerConfig {
  std::string listen = "127.0.0.1:50051";
  std::string port_file;  // written with the bound port once serving (tests use --listen ...:0)
  int max_sessions = 8;
  int max_width = 3840;
  int max_height = 2160;
  double max_fps = 120.0;
  int encoder_threads = 1;
  int render_threads = 0;  // LP_NUM_THREADS for llvmpipe; 0 = as set, else the cores + 1
  render::EglPlatformChoice renderer = render::EglPlatformChoice::kAuto;
  render::SpraySmoothing spray_smoothing = render::SpraySmoothing::kPlaneFit;
  render::WarmUp warm_up = render::WarmUp::kFull;
  std::string log_level = "info";
  std::string log_format = "text";  // or "json" (app/log_format.hpp)
  double stats_interval_s = 30.0;
  // A session whose clients have all gone quiet (no request, no Drive stream) this long is
  // closed, so a crashed simulator does not hold a session slot forever; 0 = never.
  double session_idle_timeout_s = 60.0;
  // SIGTERM drains: steps already accepted are answered, then streams end with UNAVAILABLE; the
  // process exits within this many seconds (the deploy files' stop timeout).
  double shutdown_grace_s = 30.0;
  // Admission budgets (server/session/admission.hpp): 0 = sized for the renderer and the machine
  // at start-up, -1 = none.
  double max_pixel_rate_mpx = 0.0;
  double max_memory_mb = 0.0;
  // Health turns NOT_SERVING while the render loop has not come round for this long; 0 = off.
  double watchdog_s = 10.0;
  // Security (docs/operations.md, Security). A listen address other than loopback needs TLS and a
  // tokens file, unless allow_insecure_remote says otherwise.
  std::string tokens_file;    // bearer tokens, principals and roles (rpc/auth.hpp)
  std::string tls_cert;       // PEM: the server's certificate chain ...
  std::string tls_key;        // ... and its private key
  std::string tls_client_ca;  // PEM: require client certificates signed by these (mutual TLS)
  bool allow_insecure_remote = false;
  // A plaintext listener with the health service alone, for probes that cannot speak TLS
  // (Kubernetes' gRPC probes); empty = none.
  std::string health_listen;
  // Road networks (the contract's RoadNetwork): OpenDRIVE files a session may name, in this
  // directory (empty: none); and the largest request (inline OpenDRIVE text counts), MiB.
  std::string maps_dir;
  int max_message_mb = 1;
  // Vehicle and cabin models (model/model_library.hpp) sessions may name, in this directory
  // (empty: none); the largest file (MiB) and the most triangles one may hold.
  std::string models_dir;
  int model_max_mb = 64;
  int model_max_triangles = 500'000;
  // A session's road network: the most road (km, every road's length added), which bounds the
  // time and memory its scene takes to build (on the CreateSession call's thread, not the render
  // loop's: about 40 ms and 3 MiB a km of six-lane road here).
  double max_road_km = 50.0;
  // Prometheus metrics over HTTP (app/metrics.hpp), on this host:port; empty = none.
  std::string metrics_listen;
  // The address clients reach this server at, when several serve one name (SessionInfo.endpoint);
  // empty = none.
  std::string advertise;
};

// Parses argv; on --help or an error returns the exit code to use instead of a config.
std::optional<ServerConfig> parse_config(int argc, char** argv, int* exit_code);

// Why this configuration may not start (a remote listener without TLS and tokens, half a TLS
// pair), or empty.
std::string security_problem(const ServerConfig& config);
// TLS (mutual with a client CA) when configured, else plaintext; throws if a file is unreadable.
std::shared_ptr<grpc::ServerCredentials> server_credentials(const ServerConfig& config);

// The budgets the flags ask for, the automatic ones sized for the renderer (its GL_RENDERER
// string: llvmpipe renders about 14 Mpx/s on two cores) and the memory this process may use.
session::AdmissionBudget admission_budget(const ServerConfig& config, const std::string& renderer);

}  // namespace downpour::app
