#include "server/render/gl/egl_context.hpp"

#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include <EGL/egl.h>
#include <EGL/eglext.h>

#include "server/render/gl/gl.hpp"
#include "server/sim/worker_thread.hpp"

namespace downpour::render {
namespace {

bool has_extension(const char* list, const char* name) {
  if (!list) return false;
  const std::size_t n = std::strlen(name);
  for (const char* p = list; (p = std::strstr(p, name)); p += n) {
    if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return true;
  }
  return false;
}

// The first EGL device whose driver is not Mesa's software device: a real GPU.
EGLDisplay open_gpu_device_display() {
  const char* client_ext = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  if (!has_extension(client_ext, "EGL_EXT_device_enumeration") ||
      !has_extension(client_ext, "EGL_EXT_platform_device")) {
    return EGL_NO_DISPLAY;
  }
  auto query_devices =
      reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
  auto query_device_string = reinterpret_cast<PFNEGLQUERYDEVICESTRINGEXTPROC>(
      eglGetProcAddress("eglQueryDeviceStringEXT"));
  if (!query_devices || !query_device_string) return EGL_NO_DISPLAY;
  EGLint count = 0;
  if (!query_devices(0, nullptr, &count) || count <= 0) return EGL_NO_DISPLAY;
  std::vector<EGLDeviceEXT> devices(count);
  query_devices(count, devices.data(), &count);
  for (EGLDeviceEXT device : devices) {
    const char* ext = query_device_string(device, EGL_EXTENSIONS);
    // Mesa's software device advertises EGL_MESA_device_software; skip it, surfaceless covers it.
    if (has_extension(ext, "EGL_MESA_device_software")) continue;
    EGLDisplay display = eglGetPlatformDisplay(EGL_PLATFORM_DEVICE_EXT, device, nullptr);
    if (display == EGL_NO_DISPLAY) continue;
    EGLint major = 0, minor = 0;
    if (eglInitialize(display, &major, &minor)) return display;
  }
  return EGL_NO_DISPLAY;
}

EGLDisplay open_surfaceless_display() {
  EGLDisplay display =
      eglGetPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
  if (display == EGL_NO_DISPLAY) return EGL_NO_DISPLAY;
  EGLint major = 0, minor = 0;
  return eglInitialize(display, &major, &minor) ? display : EGL_NO_DISPLAY;
}

}  // namespace

void choose_rasterizer_threads(int requested) {
  const unsigned cores = sim::usable_cores();
  const std::string threads =
      std::to_string(requested > 0 ? static_cast<unsigned>(requested) : cores + 1);
  setenv("LP_NUM_THREADS", threads.c_str(), requested > 0 ? 1 : 0);
}

std::unique_ptr<EglContext> EglContext::create(EglPlatformChoice choice) {
  std::unique_ptr<EglContext> ctx(new EglContext());
  EGLDisplay display = EGL_NO_DISPLAY;
  if (choice != EglPlatformChoice::kSurfaceless) {
    display = open_gpu_device_display();
    ctx->platform_ = "device";
  }
  if (display == EGL_NO_DISPLAY && choice == EglPlatformChoice::kDevice) {
    throw std::runtime_error("no EGL GPU device found (renderer=device)");
  }
  if (display == EGL_NO_DISPLAY) {
    display = open_surfaceless_display();
    ctx->platform_ = "surfaceless";
  }
  if (display == EGL_NO_DISPLAY)
    throw std::runtime_error("no EGL display: neither a GPU device nor Mesa surfaceless");
  ctx->display_ = display;

  if (!eglBindAPI(EGL_OPENGL_API)) throw std::runtime_error("eglBindAPI(EGL_OPENGL_API) failed");
  const EGLint config_attribs[] = {EGL_SURFACE_TYPE,
                                   EGL_PBUFFER_BIT,
                                   EGL_RENDERABLE_TYPE,
                                   EGL_OPENGL_BIT,
                                   EGL_RED_SIZE,
                                   8,
                                   EGL_GREEN_SIZE,
                                   8,
                                   EGL_BLUE_SIZE,
                                   8,
                                   EGL_NONE};
  EGLConfig config = nullptr;
  EGLint num_configs = 0;
  // Surfaceless contexts need no config; take one when offered, else go without.
  if (!eglChooseConfig(display, config_attribs, &config, 1, &num_configs) || num_configs == 0)
    config = nullptr;
  const EGLint context_attribs[] = {EGL_CONTEXT_MAJOR_VERSION,
                                    4,
                                    EGL_CONTEXT_MINOR_VERSION,
                                    5,
                                    EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                    EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                    EGL_NONE};
  EGLContext context = eglCreateContext(display, config, EGL_NO_CONTEXT, context_attribs);
  if (context == EGL_NO_CONTEXT)
    throw std::runtime_error("eglCreateContext (OpenGL 4.5 core) failed");
  ctx->context_ = context;
  if (!eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context)) {
    throw std::runtime_error("eglMakeCurrent without a surface failed");
  }
  ctx->renderer_ = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  ctx->version_ = reinterpret_cast<const char*>(glGetString(GL_VERSION));
  return ctx;
}

EglContext::~EglContext() {
  if (display_) {
    eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    if (context_) eglDestroyContext(display_, context_);
    eglTerminate(display_);
  }
}

}  // namespace downpour::render
