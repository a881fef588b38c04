// The renderer: owns the headless GL context and every GL resource, renders the views of a
// session's scene snapshot and reads their pixels back asynchronously (pixel-pack buffers and
// fences). Plain C++ interface, no GL types: the session layer drives it from the render thread.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "server/render/egl_context.hpp"
#include "server/sim/simulation.hpp"
#include "server/sim/types.hpp"

namespace downpour::render {

struct RendererOptions {
  EglPlatformChoice platform = EglPlatformChoice::kAuto;
};

struct PassTiming {
  std::string name;
  double ms = 0.0;
};

// One view's pixels on their way back from the GPU.
struct PendingReadback {
  std::uint64_t target_key = 0;
  int slot = 0;
  void* fence = nullptr;
  int width = 0;
  int height = 0;
};

class Renderer {
 public:
  // Creates the context on the calling thread, which must be the only one to use the renderer.
  // Throws std::runtime_error when no context can be made or a shader does not build.
  static std::unique_ptr<Renderer> create(const RendererOptions& options);
  ~Renderer();

  const std::string& gl_renderer() const;
  const std::string& platform() const;

  // glFinish after each pass, so that pass timings are real (benchmarks); off in service. On
  // llvmpipe a finish mid-frame leaves the context several times slower from then on, so profile
  // with a renderer of its own and take the times as a ranking of the passes.
  void set_profiling(bool on);
  const std::vector<PassTiming>& last_pass_timings() const;

  // Renders a view into the render target named target_key (made on first use, remade when the
  // size changes) and starts its readback.
  PendingReadback render(std::uint64_t target_key, const sim::ViewSpec& spec,
                         const sim::SceneState& scene);
  bool is_ready(const PendingReadback& pending) const;
  // Waits if needed; out gets RGBA8 rows bottom-up.
  void finish(const PendingReadback& pending, std::vector<std::uint8_t>& out);
  // Frees the targets whose key matches; pending readbacks of them must be finished first.
  void release_targets(const std::function<bool(std::uint64_t)>& matches);

 private:
  struct Impl;
  explicit Renderer(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// Renders one view and waits for its pixels, rows top-down (tests, tools).
std::vector<std::uint8_t> render_image(Renderer& renderer, const sim::ViewSpec& spec,
                                       const sim::SceneState& scene);

}  // namespace downpour::render
