// A headless OpenGL 4.5 core context: EGL with the device platform where a GPU driver offers one
// (NVIDIA), else Mesa's surfaceless platform (llvmpipe on machines without a GPU). No window: all
// drawing goes to framebuffer objects. Created, made current and used on one thread only.
#pragma once

#include <memory>
#include <string>

namespace downpour::render {

enum class EglPlatformChoice {
  kAuto,         // a GPU device if one exists, else surfaceless
  kDevice,       // EGL_EXT_platform_device only (fail without a GPU)
  kSurfaceless,  // Mesa surfaceless only
};

// llvmpipe's rasterizer threads (LP_NUM_THREADS): `requested` where it is above 0, else the
// environment's value where one is set, else the cores + 1. On two cores the third thread keeps a
// core busy while the other threads wait on one another: the demo delivered a median 3.6% more
// frames than with one thread a core (13 alternated pairs, 11 higher), at lower latency. Only
// Mesa's software renderer reads it. Call before any thread starts (it sets the environment).
void choose_rasterizer_threads(int requested);

class EglContext {
 public:
  // Throws std::runtime_error with the reason when no context can be made.
  static std::unique_ptr<EglContext> create(EglPlatformChoice choice);
  ~EglContext();
  EglContext(const EglContext&) = delete;
  EglContext& operator=(const EglContext&) = delete;

  const std::string& renderer() const { return renderer_; }  // GL_RENDERER
  const std::string& version() const { return version_; }    // GL_VERSION
  const std::string& platform() const { return platform_; }  // "device" or "surfaceless"

 private:
  EglContext() = default;
  void* display_ = nullptr;
  void* context_ = nullptr;
  std::string renderer_;
  std::string version_;
  std::string platform_;
};

}  // namespace downpour::render
