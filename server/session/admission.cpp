#include "server/session/admission.hpp"

#include <algorithm>
#include <cstdio>

namespace downpour::session {

SessionCost estimate_cost(const SessionConfig& config) {
  const double fps = config.fps > 0.0 ? config.fps : kLockstepNominalFps;
  SessionCost cost;
  cost.memory_bytes = kBytesPerSession;
  for (const sim::ViewSpec& v : config.views) {
    const double pixels = static_cast<double>(v.width) * v.height;
    cost.pixel_rate += pixels * fps;
    cost.memory_bytes += pixels * kBytesPerViewPixel;
    if (v.outputs.any()) cost.memory_bytes += pixels * kBytesPerGroundTruthPixel;
  }
  return cost;
}

std::string admission_refusal(const AdmissionBudget& budget, const SessionCost& used,
                              const SessionCost& add) {
  char text[256];
  // Alone on the server a session slows only itself: the pixel rate admits it whatever it asks.
  const bool alone = used.pixel_rate <= 0.0;
  if (budget.max_pixel_rate > 0.0 && !alone &&
      used.pixel_rate + add.pixel_rate > budget.max_pixel_rate) {
    std::snprintf(
        text, sizeof text,
        "pixel rate: the session asks for %.1f Mpx/s (width x height x fps over its "
        "views; lockstep counts its fps, %g if none) and %.1f of the server's %.1f Mpx/s are free "
        "(--max-pixel-rate-mpx); use fewer or smaller views or a lower fps",
        add.pixel_rate / 1e6, kLockstepNominalFps,
        std::max(0.0, budget.max_pixel_rate - used.pixel_rate) / 1e6, budget.max_pixel_rate / 1e6);
    return text;
  }
  if (budget.max_memory_bytes > 0.0 &&
      used.memory_bytes + add.memory_bytes > budget.max_memory_bytes) {
    constexpr double kMiB = 1024.0 * 1024.0;
    std::snprintf(text, sizeof text,
                  "memory: the session needs about %.0f MiB and %.0f of the server's %.0f MiB are "
                  "free (--max-memory-mb); use fewer or smaller views",
                  add.memory_bytes / kMiB,
                  std::max(0.0, budget.max_memory_bytes - used.memory_bytes) / kMiB,
                  budget.max_memory_bytes / kMiB);
    return text;
  }
  return {};
}

}  // namespace downpour::session
