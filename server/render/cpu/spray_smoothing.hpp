// How the spray's liquid body depth is smoothed (seed 001, step 4): a renderer option. No GL.
#pragma once

namespace downpour::render {

enum class SpraySmoothing {
  kPlaneFit,   // local plane fitting, 9 x 9, 3 passes: the paper's method, the default
  kBilateral,  // the bilateral filter, 7 x 7, 22 passes: the paper's baseline
  kNone,
};
const char* spray_smoothing_name(SpraySmoothing smoothing);

}  // namespace downpour::render
