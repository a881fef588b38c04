// What a view costs to render, measured the same way by every benchmark tool: whole frames with
// profiling off (wall and process CPU time, with the scene's windshield water and with dry glass),
// then each pass with profiling on in a renderer of its own (a glFinish between passes leaves an
// llvmpipe context slower for the rest of its life). Medians over the frames, after two warm-up
// frames that compile the shader variants.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "bench/stats.hpp"
#include "server/sim/simulation.hpp"

namespace downpour::bench {

struct NamedView {
  std::string name;
  sim::ViewSpec spec;
};

struct ViewCost {
  std::string name;
  int width = 0;
  int height = 0;
  double wet_ms = 0.0, wet_cpu_ms = 0.0;               // the frame with the scene's water
  double dry_ms = 0.0, dry_cpu_ms = 0.0;               // the same frame, dry glass and no blades
  std::vector<std::pair<std::string, double>> passes;  // in drawing order, median ms
  // The sum of the glass passes (glass_*, and the WINDSHIELD view's own): the windshield's cost.
  double windshield_passes_ms() const;
};

std::vector<ViewCost> measure_views(const std::vector<NamedView>& views, const sim::SceneState& wet,
                                    int frames);

}  // namespace downpour::bench
