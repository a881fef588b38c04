// Ground truth for perception tests: how much of the road a view sees in each state of the water
// model (Dry, Wet, Drench, Puddle). Pure CPU (no GL), from the view's camera, the built-in track
// and the road water window the simulation published.
#pragma once

#include "server/sim/simulation.hpp"
#include "server/sim/types.hpp"

namespace downpour::render {

struct RoadStateFractions {
  double dry = 0.0;
  double wet = 0.0;
  double drench = 0.0;
  double puddle = 0.0;  // they add up to 1 where the view sees road, else all are 0
};

// Rays through a 64 x 36 grid over the image that meet the paved road within 300 m, each classed by
// the water where it lands: the window's cell, or beyond the window its mean. The road is found
// on the plane of the road under the car, corrected once by the track's height where the ray
// lands (crests and dips ahead). What stands in front of the road (the hood, other vehicles) is
// not tested, as the view wet fraction does not test the cabin. RAIN and WINDSHIELD see no road.
RoadStateFractions view_road_states(const sim::ViewSpec& spec, const sim::SceneState& scene);

}  // namespace downpour::render
