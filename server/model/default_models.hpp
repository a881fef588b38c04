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

// Puts first the fixed triangles the driver can see past the glass's foot and counts them in
// bonnet_index_count: wholly ahead of the foot (or reaching past it no higher than the foot
// and 5 cm), not glass, facing the eye, and not wholly under the eye's sight line over the foot
// (with 6 degrees to spare, for an eye a session moves). The rest, the nose and the wings' sides
// under the dash's edge, the cabin hides. The car: 227 of its 1,804 fixed triangles, where 500 lie
// ahead of the foot (default_models_test.cpp casts rays from the eye to check).
void mark_bonnet(VehicleModel& model, const sim::GlassConfig& glass = {},
                 const glm::dvec3& eye_m = sim::EgoGeometry{}.eye_m);

// The body (null: the built-in car) marked for a session's glass and eye, for
// EgoGeometry::bonnet_model: null where both are the defaults (the library's bodies and the
// built-in car are marked for those), else a copy marked for them.
sim::ModelPtr bonnet_for(const sim::ModelPtr& body, const sim::GlassConfig& glass,
                         const glm::dvec3& eye_m);

}  // namespace downpour::model
