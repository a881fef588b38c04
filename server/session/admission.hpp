// Admission by cost: what a session will cost the server, estimated from its configuration before
// it is created, and the server's budgets. A session that would take the server past a budget is
// refused up front, saying which budget and by how much, instead of starving the others later.
#pragma once

#include <string>

#include "server/session/session.hpp"

namespace downpour::session {

struct SessionCost {
  double pixel_rate = 0.0;    // pixels rendered and encoded per second, over its views
  double memory_bytes = 0.0;  // render targets, readback and encoder buffers, its simulation
};

// A lockstep session is counted at the fps it was created with (the step rate its client expects),
// this one if none. Alone on an empty server, any session passes the pixel-rate budget.
constexpr double kLockstepNominalFps = 30.0;
// Measured on the server (docs/operations.md, Admission): resident memory per pixel of a view (its
// targets, the glass passes' targets, readback buffers, the encoder's copy and output; on llvmpipe
// a second colour and depth and the kept cabin's picture, 16 of the 36) and per session (the
// simulation, the glass water map, the session's GL state); and, beside those 16 MB, the water's
// surface on the GPU (some 3 MB in heavy rain) and the environment probe (1.2 MB).
constexpr double kBytesPerViewPixel = 36.0;
constexpr double kBytesPerSession = 20.0 * 1024 * 1024;
// A view that asks for ground truth (sim::Outputs), per pixel, counted from what it holds: the
// clean frame's texture, two readback buffers and the encoder's copy (16 bytes), the depth's two
// readback buffers, its distances and its centimetres (14).
constexpr double kBytesPerGroundTruthPixel = 30.0;

SessionCost estimate_cost(const SessionConfig& config);

struct AdmissionBudget {
  double max_pixel_rate = 0.0;    // pixels per second; 0 = no limit
  double max_memory_bytes = 0.0;  // 0 = no limit
};

// Empty when a session of cost `add` fits beside `used`; else why not, for RESOURCE_EXHAUSTED.
std::string admission_refusal(const AdmissionBudget& budget, const SessionCost& used,
                              const SessionCost& add);

}  // namespace downpour::session
