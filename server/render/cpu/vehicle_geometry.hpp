// The ego vehicle's shape in the vehicle frame (x forward from the rear axle, y left, z up): a
// simple car body for outside views, and the cockpit interior that frames the driver's view.
#pragma once

#include <glm/vec3.hpp>

#include "server/render/cpu/mesh_data.hpp"
#include "server/render/cpu/shader_interface.hpp"
#include "server/sim/windshield.hpp"

namespace downpour::render {

// The windshield's corners in the vehicle frame, from the simulation's glass.
struct WindshieldCorners {
  glm::vec3 bottom_right;
  glm::vec3 bottom_left;
  glm::vec3 top_left;
  glm::vec3 top_right;
};
WindshieldCorners windshield_corners(const sim::GlassConfig& glass);

// (Material ids, carried in uv.x: shader_interface.hpp's material::.)

// A passenger car about 4.6 x 1.8 x 1.47 m: the hull (the lower body, whose hood shows from the
// driver's seat) and the rest (cabin, roof, wheels, lamps).
MeshData build_car_hull();
MeshData build_car_upper();
// The other classes' shapes at their usual sizes (sim/vehicle_class.hpp), whole: a rigid truck
// (cab, box body, wheels), a city bus (body, window band), a motorbike with its rider.
MeshData build_truck();
MeshData build_bus();
MeshData build_motorbike();
// Dashboard, A-pillars, roof edge and mirror as seen from the driver's seat.
MeshData build_cockpit_interior(const sim::GlassConfig& glass);
// Whether two glasses give the same cockpit interior (the fields it is built from).
bool same_cockpit_interior(const sim::GlassConfig& a, const sim::GlassConfig& b);

}  // namespace downpour::render
