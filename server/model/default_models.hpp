// The built-in models, used where a session names none: a car, a rigid truck, a city bus and a
// motorbike with its rider, at their classes' sizes (sim/vehicle_class.hpp), with rounded bodies,
// windows, lamps where the lights are and wheels that turn; and the driver's cabin round the
// simulated glass. Built as code, from shapes.hpp; `downpour-models export` writes them as glTF
// for vendors to start from.
#pragma once

#include "server/model/vehicle_model.hpp"
#include "server/sim/types.hpp"
#include "server/sim/windshield.hpp"

namespace downpour::model {

// How finely a model is cut: in full, or for the distance (a few thousand triangles against a few
// hundred, plain boxes, and wheels that do not turn, drawn with the rest at once: the renderer
// draws vehicles far away, small in the picture, in the second).
enum class Detail { kFull, kFar };
VehicleModel default_vehicle(sim::VehicleClass c, Detail detail = Detail::kFull);
// Dashboard, instrument hood, A-pillars along the glass's side edges, roof liner and rear-view
// mirror, seen from the driver's seat; its windshield outline is the glass's own.
VehicleModel default_cabin(const sim::GlassConfig& glass);
// Whether two glasses give the same cabin (the fields it is built from).
bool same_cabin(const sim::GlassConfig& a, const sim::GlassConfig& b);

// Puts first the fixed triangles that lie wholly ahead of x (the bonnet and wings seen from the
// driver's seat, x the windshield's foot) and counts them in bonnet_index_count.
void mark_bonnet(VehicleModel& model, float ahead_of_x);

}  // namespace downpour::model
