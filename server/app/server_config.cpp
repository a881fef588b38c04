#include "server/app/server_config.hpp"

#include <map>

#include <CLI/CLI.hpp>

namespace downpour::app {

std::optional<ServerConfig> parse_config(int argc, char** argv, int* exit_code) {
  ServerConfig c;
  CLI::App app{"Downpour: renders rain for driving simulators and streams JPEG frames over gRPC."};
  app.option_defaults()->always_capture_default();
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
                 "llvmpipe rasterizer threads (LP_NUM_THREADS); 0 = as set")
      ->check(CLI::Range(0, 64))
      ->envname("DOWNPOUR_RENDER_THREADS");
  const std::map<std::string, render::EglPlatformChoice> renderers{
      {"auto", render::EglPlatformChoice::kAuto},
      {"device", render::EglPlatformChoice::kDevice},
      {"surfaceless", render::EglPlatformChoice::kSurfaceless}};
  app.add_option("--renderer", c.renderer, "auto: a GPU's EGL device if any, else Mesa surfaceless")
      ->transform(CLI::CheckedTransformer(renderers, CLI::ignore_case))
      ->envname("DOWNPOUR_RENDERER");
  app.add_option("--log-level", c.log_level, "trace, debug, info, warn, error")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error"}))
      ->envname("DOWNPOUR_LOG_LEVEL");
  app.add_option("--stats-interval", c.stats_interval_s, "seconds between stats lines in the log")
      ->check(CLI::Range(1.0, 3600.0));
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    *exit_code = app.exit(e);
    return std::nullopt;
  }
  return c;
}

}  // namespace downpour::app
