// Ground truth for perception tests: how much of a view the water on the windshield hides. Pure
// CPU (no GL), from the view's camera and the water's surface on the glass.
#pragma once

#include "server/sim/simulation.hpp"
#include "server/sim/types.hpp"

namespace downpour::render {

// The fraction of a COCKPIT view's rays (a 64 x 36 grid over the image) that cross the glass
// under water (sim::GlassWaterSurface::top_height); 0 for the other views. Rays through the glass
// are counted whatever the cabin hides of it (pillars, mirror), which is little: the cabin frames
// the glass.
double view_wet_fraction(const sim::ViewSpec& spec, const sim::SceneState& scene);

}  // namespace downpour::render
