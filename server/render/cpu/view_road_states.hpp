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
// the water where it lands: the finest ring's cell that holds it, or beyond the rings their mean.
// The road is found on the plane of the road under the car, corrected once by the track's height
// where the ray lands (crests and dips ahead). A ray that meets a vehicle first (a box around its
// body down to the road: the hood from the driver's seat, the ego car from outside, the traffic)
// sees no road. RAIN and WINDSHIELD see no road.
RoadStateFractions view_road_states(const sim::ViewSpec& spec, const sim::SceneState& scene);

}  // namespace downpour::render
