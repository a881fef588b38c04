// The server's configuration: command-line flags (CLI11), each also settable from an environment
// variable (DOWNPOUR_<FLAG>) for containers.
#pragma once

#include <optional>
#include <string>

#include "server/render/egl_context.hpp"

namespace downpour::app {

struct ServerConfig {
  std::string listen = "127.0.0.1:50051";
  std::string port_file;  // written with the bound port once serving (tests use --listen ...:0)
  int max_sessions = 8;
  int max_width = 3840;
  int max_height = 2160;
  double max_fps = 120.0;
  int encoder_threads = 1;
  int render_threads = 0;  // LP_NUM_THREADS for llvmpipe; 0 = leave the environment's value
  render::EglPlatformChoice renderer = render::EglPlatformChoice::kAuto;
  std::string log_level = "info";
  double stats_interval_s = 30.0;
};

// Parses argv; on --help or an error returns the exit code to use instead of a config.
std::optional<ServerConfig> parse_config(int argc, char** argv, int* exit_code);

}  // namespace downpour::app
