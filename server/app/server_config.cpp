#include "server/app/server_config.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <vector>

#include <CLI/CLI.hpp>

#include "server/rpc/auth.hpp"

namespace downpour::app {

const char* const kVersion = DOWNPOUR_VERSION;

namespace {

std::string read_file(const std::string& path, const char* what) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(std::string(what) + ": cannot read " + path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// The machine's memory, or the container's limit if lower (cgroup v2's memory.max, or v1's
// limit_in_bytes, which reads as a huge number when there is none).
double available_memory_bytes() {
  double bytes = static_cast<double>(sysconf(_SC_PHYS_PAGES)) * sysconf(_SC_PAGESIZE);
  for (const char* path :
       {"/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory/memory.limit_in_bytes"}) {
    std::ifstream limit(path);
    double cgroup = 0.0;
    if (limit >> cgroup && cgroup > 0.0) bytes = std::min(bytes, cgroup);  // "max" reads as none
  }
  return bytes;
}

// The options of where it listens and what it takes on: sessions, their views and frame rates,
// the threads that render and encode them.
void add_serving_options(CLI::App& app, ServerConfig& c) {
  app.add_option("--listen", c.listen, "address to listen on (host:port; port 0 picks a free one)")
      ->envname("DOWNPOUR_LISTEN");
  app.add_option("--port-file", c.port_file, "write the bound port to this file once serving");
  app.add_option("--max-sessions", c.max_sessions, "most sessions at once")
      ->check(CLI::Range(1, 256))
      ->envname("DOWNPOUR_MAX_SESSIONS");
  app.add_option("--max-width", c.max_width, "largest view width")
      ->check(CLI::Range(16, 8192))
      ->envname("DOWNPOUR_MAX_WIDTH");
  app.add_option("--max-height", c.max_height, "largest view height")
      ->check(CLI::Range(16, 8192))
      ->envname("DOWNPOUR_MAX_HEIGHT");
  app.add_option("--max-fps", c.max_fps, "highest realtime frame rate a session may ask for")
      ->check(CLI::Range(1.0, 1000.0))
      ->envname("DOWNPOUR_MAX_FPS");
  app.add_option("--encoder-threads", c.encoder_threads, "JPEG encoder threads")
      ->check(CLI::Range(1, 64))
      ->envname("DOWNPOUR_ENCODER_THREADS");
  app.add_option("--render-threads", c.render_threads,
                 "llvmpipe rasterizer threads (LP_NUM_THREADS); 0 = as set, else the cores + 1")
      ->check(CLI::Range(0, 64))
      ->envname("DOWNPOUR_RENDER_THREADS");
}

// Named choices are read as text and mapped after parsing (apply_choices), so that --help lists
// the names.
struct NamedChoices {
  std::string renderer = "auto";
  std::string smoothing = "plane_fit";
  std::string warm_up = "full";
};

void add_choice_options(CLI::App& app, NamedChoices& choices) {
  app.add_option("--renderer", choices.renderer,
                 "device: a GPU's EGL device; surfaceless: Mesa (llvmpipe on the CPU); auto: a "
                 "device if there is one, else surfaceless")
      ->check(CLI::IsMember({"auto", "device", "surfaceless"}, CLI::ignore_case))
      ->envname("DOWNPOUR_RENDERER");
  app.add_option("--spray-smoothing", choices.smoothing,
                 "the spray's liquid surface: plane_fit (9x9, 3 passes), bilateral (7x7, 22 "
                 "passes) or none")
      ->check(CLI::IsMember({"plane_fit", "bilateral", "none"}, CLI::ignore_case))
      ->envname("DOWNPOUR_SPRAY_SMOOTHING");
  app.add_option("--warm-up", choices.warm_up,
                 "before serving: full draws the common scenes small so that llvmpipe compiles "
                 "their shaders then, not in a session's stream (2 s; 6 s without Mesa's shader "
                 "cache); minimal proves the context with one tiny frame (tests of the protocol)")
      ->check(CLI::IsMember({"full", "minimal"}, CLI::ignore_case))
      ->envname("DOWNPOUR_WARM_UP");
}

// The parsed choices' names (any case) into their values.
void apply_choices(NamedChoices choices, ServerConfig& c) {
  const std::map<std::string, render::EglPlatformChoice> renderers{
      {"auto", render::EglPlatformChoice::kAuto},
      {"device", render::EglPlatformChoice::kDevice},
      {"surfaceless", render::EglPlatformChoice::kSurfaceless}};
  const std::map<std::string, render::SpraySmoothing> smoothings{
      {"plane_fit", render::SpraySmoothing::kPlaneFit},
      {"bilateral", render::SpraySmoothing::kBilateral},
      {"none", render::SpraySmoothing::kNone}};
  const std::map<std::string, render::WarmUp> warm_ups{{"full", render::WarmUp::kFull},
                                                       {"minimal", render::WarmUp::kMinimal}};
  for (std::string* name : {&choices.renderer, &choices.smoothing, &choices.warm_up})
    std::transform(name->begin(), name->end(), name->begin(), ::tolower);
  c.renderer = renderers.at(choices.renderer);
  c.spray_smoothing = smoothings.at(choices.smoothing);
  c.warm_up = warm_ups.at(choices.warm_up);
}

// The options of running it: its log, the sessions' idle timeout, the drain's grace, the
// admission budgets and the watchdog.
void add_operation_options(CLI::App& app, ServerConfig& c) {
  app.add_option("--log-level", c.log_level, "trace, debug, info, warn, error")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error"}))
      ->envname("DOWNPOUR_LOG_LEVEL");
  app.add_option("--log-format", c.log_format,
                 "text, or json: one object a line (time, level, session, msg)")
      ->check(CLI::IsMember({"text", "json"}))
      ->envname("DOWNPOUR_LOG_FORMAT");
  app.add_option("--stats-interval", c.stats_interval_s, "seconds between stats lines in the log")
      ->check(CLI::Range(1.0, 3600.0));
  app.add_option("--session-idle-timeout-s", c.session_idle_timeout_s,
                 "close a session no client has been heard for (no request, no Drive stream) "
                 "this long; 0 = never")
      ->check(CLI::Range(0.0, 86400.0))
      ->envname("DOWNPOUR_SESSION_IDLE_TIMEOUT_S");
  app.add_option("--shutdown-grace-s", c.shutdown_grace_s,
                 "on SIGTERM, answer the steps in flight and exit within this many seconds")
      ->check(CLI::Range(1.0, 3600.0))
      ->envname("DOWNPOUR_SHUTDOWN_GRACE_S");
  app.add_option(
         "--max-pixel-rate-mpx", c.max_pixel_rate_mpx,
         "budget of pixels per second (Mpx/s) over all sessions' views; a session that "
         "would pass it is refused. 0 = by renderer (60 on llvmpipe, 2000 on a GPU), a negative "
         "value = none")
      ->check(CLI::Range(-1.0, 1e6))
      ->envname("DOWNPOUR_MAX_PIXEL_RATE_MPX");
  app.add_option("--max-memory-mb", c.max_memory_mb,
                 "budget of the sessions' estimated memory (MiB). 0 = half of the machine's (or "
                 "the container's) memory, a negative value = none")
      ->check(CLI::Range(-1.0, 1e8))
      ->envname("DOWNPOUR_MAX_MEMORY_MB");
  app.add_option("--watchdog-s", c.watchdog_s,
                 "health turns NOT_SERVING while the render loop has not come round for this "
                 "long (a hung GPU, a frame far over its budget); 0 = off")
      ->check(CLI::Range(0.0, 3600.0))
      ->envname("DOWNPOUR_WATCHDOG_S");
}

// The options of who may reach it and how: tokens, TLS, listening beyond loopback, the
// plaintext health port.
void add_security_options(CLI::App& app, ServerConfig& c) {
  app.add_option("--tokens-file", c.tokens_file,
                 "bearer tokens with their principals and roles, one per line: token principal "
                 "driver|viewer|admin[,...]; without it every client may do everything")
      ->envname("DOWNPOUR_TOKENS_FILE");
  app.add_option("--tls-cert", c.tls_cert, "PEM certificate chain: serve TLS")
      ->envname("DOWNPOUR_TLS_CERT");
  app.add_option("--tls-key", c.tls_key, "PEM private key of --tls-cert")
      ->envname("DOWNPOUR_TLS_KEY");
  app.add_option("--tls-client-ca", c.tls_client_ca,
                 "PEM CA certificates: require client certificates they sign (mutual TLS)")
      ->envname("DOWNPOUR_TLS_CLIENT_CA");
  app.add_flag("--allow-insecure-remote", c.allow_insecure_remote,
               "listen beyond loopback without TLS and tokens (a network you trust)")
      ->envname("DOWNPOUR_ALLOW_INSECURE_REMOTE");
  app.add_option("--health-listen", c.health_listen,
                 "also serve grpc.health.v1 alone, in plaintext, here (for probes without TLS)")
      ->envname("DOWNPOUR_HEALTH_LISTEN");
}

// The options of road networks: the maps, the request size inline ones need, the most road.
void add_road_options(CLI::App& app, ServerConfig& c) {
  app.add_option("--maps-dir", c.maps_dir,
                 "OpenDRIVE maps (.xodr) that CreateSession may name (roads.map_name)")
      ->check(CLI::ExistingDirectory)
      ->envname("DOWNPOUR_MAPS_DIR");
  app.add_option("--max-message-mb", c.max_message_mb,
                 "largest request in MiB (raise it for inline OpenDRIVE roads; files are refused "
                 "beyond 64)")
      ->check(CLI::Range(1, 64))
      ->envname("DOWNPOUR_MAX_MESSAGE_MB");
  app.add_option("--models-dir", c.models_dir,
                 "glTF 2.0 vehicle and cabin models (.glb, .gltf) that sessions may name "
                 "(ego.body_model, ego.cabin_model, TrafficVehicle.model)")
      ->check(CLI::ExistingDirectory)
      ->envname("DOWNPOUR_MODELS_DIR");
  app.add_option("--model-max-mb", c.model_max_mb,
                 "the largest model file, with the buffers beside it that it names, MiB")
      ->check(CLI::Range(1, 1024))
      ->envname("DOWNPOUR_MODEL_MAX_MB");
  app.add_option("--model-max-triangles", c.model_max_triangles,
                 "the most triangles a model may have")
      ->check(CLI::Range(1000, 10'000'000))
      ->envname("DOWNPOUR_MODEL_MAX_TRIANGLES");
  app.add_option("--max-road-km", c.max_road_km,
                 "the most road a session's network may have, km (every road's length added)")
      ->check(CLI::Range(0.1, 1000.0))
      ->envname("DOWNPOUR_MAX_ROAD_KM");
}

// The options of what it offers beside the service: the metrics endpoint, the address it
// advertises.
void add_endpoint_options(CLI::App& app, ServerConfig& c) {
  app.add_option("--metrics-listen", c.metrics_listen,
                 "serve Prometheus metrics over HTTP at /metrics here (host:port); empty = none")
      ->envname("DOWNPOUR_METRICS_LISTEN");
  app.add_option("--advertise", c.advertise,
                 "the address clients reach this server at (host:port), told in SessionInfo."
                 "endpoint so that they follow a session to the server that holds it (several "
                 "servers behind one name); empty = none")
      ->envname("DOWNPOUR_ADVERTISE");
}

// The command line, with DOWNPOUR_CONFIG given as --config unless the command line names a file
// (CLI11 reads no environment variable for the config option itself).
std::vector<std::string> args_with_config_env(int argc, char** argv) {
  std::vector<std::string> args(argv, argv + argc);
  const char* config_env = std::getenv("DOWNPOUR_CONFIG");
  if (config_env && *config_env && std::find(args.begin(), args.end(), "--config") == args.end()) {
    args.insert(args.begin() + 1, {"--config", config_env});
  }
  return args;
}

}  // namespace

std::string security_problem(const ServerConfig& c) {
  if (c.tls_cert.empty() != c.tls_key.empty()) return "--tls-cert and --tls-key go together";
  if (!c.tls_client_ca.empty() && c.tls_cert.empty())
    return "--tls-client-ca needs --tls-cert and --tls-key";
  if (!rpc::loopback_only(c.listen) && !c.allow_insecure_remote &&
      (c.tls_cert.empty() || c.tokens_file.empty())) {
    return "listening on " + c.listen +
           " reaches other machines: give --tls-cert, --tls-key and --tokens-file (docs/"
           "operations.md, Security), or --allow-insecure-remote on a network you trust";
  }
  return {};
}

std::shared_ptr<grpc::ServerCredentials> server_credentials(const ServerConfig& c) {
  if (c.tls_cert.empty()) return grpc::InsecureServerCredentials();
  grpc::SslServerCredentialsOptions options(
      c.tls_client_ca.empty() ? GRPC_SSL_DONT_REQUEST_CLIENT_CERTIFICATE
                              : GRPC_SSL_REQUEST_AND_REQUIRE_CLIENT_CERTIFICATE_AND_VERIFY);
  options.pem_key_cert_pairs.push_back(
      {read_file(c.tls_key, "--tls-key"), read_file(c.tls_cert, "--tls-cert")});
  if (!c.tls_client_ca.empty())
    options.pem_root_certs = read_file(c.tls_client_ca, "--tls-client-ca");
  return grpc::SslServerCredentials(options);
}

session::AdmissionBudget admission_budget(const ServerConfig& config, const std::string& renderer) {
  session::AdmissionBudget b;
  const bool software = renderer.find("llvmpipe") != std::string::npos ||
                        renderer.find("softpipe") != std::string::npos;
  if (config.max_pixel_rate_mpx > 0.0) {
    b.max_pixel_rate = config.max_pixel_rate_mpx * 1e6;
  } else if (config.max_pixel_rate_mpx == 0.0) {
    b.max_pixel_rate = (software ? 60.0 : 2000.0) * 1e6;
  }
  if (config.max_memory_mb > 0.0) {
    b.max_memory_bytes = config.max_memory_mb * 1024.0 * 1024.0;
  } else if (config.max_memory_mb == 0.0) {
    b.max_memory_bytes = available_memory_bytes() / 2.0;
  }
  return b;
}

std::optional<ServerConfig> parse_config(int argc, char** argv, int* exit_code) {
  ServerConfig c;
  CLI::App app{"Downpour: renders rain for driving simulators and streams JPEG frames over gRPC."};
  // A flag given twice takes its last value (a wrapper script's defaults, then the caller's).
  app.option_defaults()->always_capture_default()->multi_option_policy(
      CLI::MultiOptionPolicy::TakeLast);
  // (In this order, which --help keeps.)
  add_serving_options(app, c);
  NamedChoices choices;
  add_choice_options(app, choices);
  add_operation_options(app, c);
  add_security_options(app, c);
  add_road_options(app, c);
  add_endpoint_options(app, c);
  app.set_version_flag("--version", std::string("downpour-server ") + kVersion);
  app.set_config("--config", "",
                 "read flags from this file (TOML or INI: one `flag = value` a line, without "
                 "the dashes; also DOWNPOUR_CONFIG). The command line wins over the file, the "
                 "file over the environment's DOWNPOUR_<FLAG>");
  std::vector<std::string> args = args_with_config_env(argc, argv);
  std::vector<char*> arg_pointers;
  for (std::string& a : args) arg_pointers.push_back(a.data());
  try {
    app.parse(static_cast<int>(arg_pointers.size()), arg_pointers.data());
  } catch (const CLI::ParseError& e) {
    // --help and --version exit 0; every refused configuration exits 2, as a server that will
    // not start for its security does.
    *exit_code = app.exit(e) == 0 ? 0 : 2;
    return std::nullopt;
  }
  apply_choices(std::move(choices), c);
  return c;
}

}  // namespace downpour::app
