#include "server/render/cpu/vehicle_geometry.hpp"

#include <initializer_list>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>

#include "server/sim/car_body.hpp"
#include "server/sim/vehicle_class.hpp"

namespace downpour::render {

MeshData build_car_hull() {
  MeshData m;
  // Lower body from the rear bumper (x = -0.95) to the front bumper (x = 3.65).
  namespace body = sim::car_body;
  const auto top = static_cast<float>(body::kHullTopZ);
  const auto half = static_cast<float>(body::kHullHalfWidth);
  m.add_frustum({-0.95f, -0.9f, 0.28f}, {3.65f, 0.9f, top},
                {static_cast<float>(body::kHullRearX), -half},
                {static_cast<float>(body::kHullFrontX), half}, material::kBody);
  return m;
}

MeshData build_car_upper() {
  MeshData m;
  // Cabin: glass house narrowing towards the roof.
  namespace body = sim::car_body;
  const auto cabin_half = static_cast<float>(body::kCabinHalfWidth);
  m.add_frustum(
      {static_cast<float>(body::kCabinRearX), -cabin_half, static_cast<float>(body::kHullTopZ)},
      {static_cast<float>(body::kCabinFrontX), cabin_half, 1.45f}, {-0.2f, -0.7f}, {1.4f, 0.7f},
      material::kGlass);
  const auto roof_half = static_cast<float>(body::kRoofHalfWidth);
  m.add_box({static_cast<float>(body::kRoofRearX), -roof_half, 1.44f},
            {static_cast<float>(body::kRoofFrontX), roof_half, static_cast<float>(body::kRoofZ)},
            material::kBody);  // roof panel
  // Wheels: radius 0.33 at the axles x = 0 and x = 2.7.
  for (float x : {0.0f, 2.7f}) {
    for (float y : {-0.8f, 0.8f}) {
      m.add_box({x - 0.33f, y - 0.11f, 0.0f}, {x + 0.33f, y + 0.11f, 0.66f}, material::kTyre);
    }
  }
  // Lamps: tail (and brake) lamps and headlamps, with an indicator beside or under each.
  for (float side : {1.0f, -1.0f}) {
    auto y = [side](float a, float b) { return side > 0 ? glm::vec2(a, b) : glm::vec2(-b, -a); };
    const float indicator = side > 0 ? material::kIndicatorLeft : material::kIndicatorRight;
    m.add_box({-0.97f, y(0.55f, 0.85f).x, 0.72f}, {-0.93f, y(0.55f, 0.85f).y, 0.85f},
              material::kLamp);
    m.add_box({-0.97f, y(0.6f, 0.85f).x, 0.64f}, {-0.93f, y(0.6f, 0.85f).y, 0.71f}, indicator);
    m.add_box({3.59f, y(0.48f, 0.76f).x, 0.62f}, {3.665f, y(0.48f, 0.76f).y, 0.74f},
              material::kHeadlamp);
    m.add_box({3.59f, y(0.77f, 0.86f).x, 0.62f}, {3.665f, y(0.77f, 0.86f).y, 0.7f}, indicator);
  }
  return m;
}

namespace {

// Lamps at the front (x = front) and back (x = rear) of a wide vehicle: a headlamp with an
// indicator outboard of it, a tail lamp with an indicator under it, each side; centred on the
// layout's lamp positions.
void add_lamps(MeshData& m, const sim::VehicleLayout& l, float front) {
  for (float side : {1.0f, -1.0f}) {
    const float indicator = side > 0 ? material::kIndicatorLeft : material::kIndicatorRight;
    const auto hy = static_cast<float>(l.headlamp_m.y), hz = static_cast<float>(l.headlamp_m.z);
    const auto ty = static_cast<float>(l.tail_lamp_m.y), tz = static_cast<float>(l.tail_lamp_m.z);
    const auto rear = static_cast<float>(l.rear_m);
    const auto span = [side](float a, float b) {
      return side > 0 ? glm::vec2(a, b) : glm::vec2(-b, -a);
    };
    m.add_box({front - 0.04f, span(hy - 0.15f, hy + 0.15f).x, hz - 0.08f},
              {front + 0.02f, span(hy - 0.15f, hy + 0.15f).y, hz + 0.08f}, material::kHeadlamp);
    m.add_box({front - 0.04f, span(hy + 0.17f, hy + 0.25f).x, hz - 0.06f},
              {front + 0.02f, span(hy + 0.17f, hy + 0.25f).y, hz + 0.06f}, indicator);
    m.add_box({rear - 0.02f, span(ty - 0.12f, ty + 0.12f).x, tz - 0.1f},
              {rear + 0.04f, span(ty - 0.12f, ty + 0.12f).y, tz + 0.1f}, material::kLamp);
    m.add_box({rear - 0.02f, span(ty - 0.12f, ty + 0.12f).x, tz - 0.22f},
              {rear + 0.04f, span(ty - 0.12f, ty + 0.12f).y, tz - 0.12f}, indicator);
  }
}

void add_wheels(MeshData& m, std::initializer_list<float> axles, float half_track, float radius,
                float width) {
  for (float x : axles) {
    for (float y : {-half_track, half_track}) {
      m.add_box({x - radius, y - 0.5f * width, 0.0f}, {x + radius, y + 0.5f * width, 2.0f * radius},
                material::kTyre);
    }
  }
}

}  // namespace

MeshData build_truck() {
  const sim::VehicleLayout& l = sim::vehicle_layout(sim::VehicleClass::kTruck);
  MeshData m;
  const float front = static_cast<float>(l.rear_m + l.size_m.x);  // 9.0
  // Chassis rails, the cab (its lower part body, its windows glass, a roof) and the box body.
  m.add_box({-3.0f, -0.5f, 0.55f}, {front - 0.3f, 0.5f, 1.0f}, material::kTrim);
  m.add_box({front - 2.3f, -1.25f, 0.45f}, {front, 1.25f, 1.9f}, material::kBody);
  m.add_frustum({front - 2.3f, -1.22f, 1.9f}, {front - 0.05f, 1.22f, 2.75f}, {front - 2.3f, -1.2f},
                {front - 0.25f, 1.2f}, material::kGlass);
  m.add_box({front - 2.3f, -1.24f, 2.75f}, {front - 0.2f, 1.24f, 3.2f}, material::kBody);
  m.add_box({-3.0f, -1.25f, 1.0f}, {front - 2.45f, 1.25f, 3.8f}, material::kBody);
  add_wheels(m, {-0.65f, 0.65f, 7.5f}, 1.0f, 0.5f, 0.4f);
  add_lamps(m, l, front);
  return m;
}

MeshData build_bus() {
  const sim::VehicleLayout& l = sim::vehicle_layout(sim::VehicleClass::kBus);
  MeshData m;
  const float front = static_cast<float>(l.rear_m + l.size_m.x);  // 8.6
  const float half = static_cast<float>(0.5 * l.size_m.y);
  // A box: the lower body, a band of windows (the windscreen down to 1 m at the front), the roof.
  m.add_box({-3.4f, -half, 0.3f}, {front, half, 1.15f}, material::kBody);
  m.add_box({-3.4f, -half + 0.02f, 1.15f}, {front - 0.02f, half - 0.02f, 2.7f}, material::kGlass);
  m.add_box({-3.4f, -half, 2.7f}, {front, half, 3.2f}, material::kBody);
  m.add_box({-3.4f, -half - 0.01f, 1.15f}, {-2.6f, half + 0.01f, 2.7f}, material::kBody);  // back
  add_wheels(m, {0.0f, 6.0f}, 1.0f, 0.5f, 0.3f);
  add_lamps(m, l, front);
  return m;
}

MeshData build_motorbike() {
  const sim::VehicleLayout& l = sim::vehicle_layout(sim::VehicleClass::kMotorbike);
  MeshData m;
  // Two wheels 1.45 m apart, the tank and seat between, forks; the rider sitting up, helmeted.
  add_wheels(m, {0.0f, 1.45f}, 0.0f, 0.32f, 0.14f);
  m.add_box({0.05f, -0.17f, 0.45f}, {1.25f, 0.17f, 0.9f}, material::kBody);
  m.add_box({1.2f, -0.08f, 0.4f}, {1.5f, 0.08f, 1.0f}, material::kTrim);
  m.add_box({0.3f, -0.2f, 0.9f}, {0.7f, 0.2f, 1.27f}, material::kTrim);      // the rider
  m.add_box({0.6f, -0.3f, 1.05f}, {1.2f, 0.3f, 1.15f}, material::kTrim);     // arms to the bars
  m.add_box({0.38f, -0.14f, 1.27f}, {0.66f, 0.14f, 1.5f}, material::kBody);  // helmet
  const auto hx = static_cast<float>(l.headlamp_m.x), hz = static_cast<float>(l.headlamp_m.z);
  const auto tx = static_cast<float>(l.tail_lamp_m.x), tz = static_cast<float>(l.tail_lamp_m.z);
  m.add_box({hx - 0.12f, -0.09f, hz - 0.08f}, {hx, 0.09f, hz + 0.08f}, material::kHeadlamp);
  m.add_box({tx, -0.08f, tz - 0.05f}, {tx + 0.08f, 0.08f, tz + 0.05f}, material::kLamp);
  m.add_box({tx, 0.1f, tz - 0.03f}, {tx + 0.05f, 0.18f, tz + 0.03f}, material::kIndicatorLeft);
  m.add_box({tx, -0.18f, tz - 0.03f}, {tx + 0.05f, -0.1f, tz + 0.03f}, material::kIndicatorRight);
  m.add_box({0.0f, -0.1f, 0.6f}, {0.2f, 0.1f, 0.8f}, material::kTrim);  // the tail
  m.add_box({tx, -0.08f, tz - 0.1f}, {0.05f, 0.08f, tz - 0.02f}, material::kTrim);
  return m;
}

WindshieldCorners windshield_corners(const sim::GlassConfig& glass) {
  const double inset = glass.inset_mm(glass.height_mm);
  return {glm::vec3(glass.to_vehicle({glass.bottom_width_mm, 0.0})),
          glm::vec3(glass.to_vehicle({0.0, 0.0})),
          glm::vec3(glass.to_vehicle({inset, glass.height_mm})),
          glm::vec3(glass.to_vehicle({glass.bottom_width_mm - inset, glass.height_mm}))};
}

bool same_cockpit_interior(const sim::GlassConfig& a, const sim::GlassConfig& b) {
  return a.bottom_left_m == b.bottom_left_m && a.bottom_width_mm == b.bottom_width_mm &&
         a.top_width_mm == b.top_width_mm && a.height_mm == b.height_mm && a.rake_deg == b.rake_deg;
}

MeshData build_cockpit_interior(const sim::GlassConfig& glass) {
  const WindshieldCorners g = windshield_corners(glass);
  MeshData m;
  const float dash_back = 1.45f;
  // Dashboard top: from the glass's lower edge back towards the driver, slightly lower at the back.
  m.add_face({dash_back, -0.85f, g.bottom_left.z - 0.03f},
             {g.bottom_right.x, -0.85f, g.bottom_right.z - 0.005f},
             {g.bottom_left.x, 0.85f, g.bottom_left.z - 0.005f},
             {dash_back, 0.85f, g.bottom_left.z - 0.03f}, material::kTrim);
  // Its face towards the driver.
  m.add_face({dash_back, 0.85f, 0.55f}, {dash_back, -0.85f, 0.55f},
             {dash_back, -0.85f, g.bottom_left.z - 0.03f},
             {dash_back, 0.85f, g.bottom_left.z - 0.03f}, material::kTrim);
  // Instrument hood in front of the driver.
  m.add_frustum({dash_back - 0.02f, 0.17f, 0.9f}, {1.78f, 0.57f, 1.03f}, {dash_back, 0.2f},
                {1.66f, 0.54f}, material::kTrim);
  // A-pillars along the glass's side edges, 9 cm wide, 6 cm deep.
  for (int side : {-1, 1}) {
    const glm::vec3 lo = side > 0 ? g.bottom_left : g.bottom_right;
    const glm::vec3 hi = side > 0 ? g.top_left : g.top_right;
    const glm::vec3 out(0.0f, side * 0.09f, 0.0f);
    const glm::vec3 in(-0.04f, 0.0f, -0.05f);
    // Inner face, seen from the cabin, and the side face towards the glass.
    if (side > 0) {
      m.add_face(lo + in, hi + in, hi + out + in, lo + out + in, material::kTrim);
      m.add_face(lo, hi, hi + in, lo + in, material::kTrim);
    } else {
      m.add_face(lo + in, lo + out + in, hi + out + in, hi + in, material::kTrim);
      m.add_face(lo, lo + in, hi + in, hi, material::kTrim);
    }
  }
  // Roof liner from just inside the glass's top edge back over the driver: it hides the edge, so
  // that the water drawn on the glass stops where the liner begins.
  m.add_face({g.top_right.x - 0.03f, -0.9f, g.top_right.z - 0.01f},
             {g.top_left.x - 0.03f, 0.9f, g.top_left.z - 0.01f}, {0.2f, 0.9f, g.top_left.z + 0.06f},
             {0.2f, -0.9f, g.top_right.z + 0.06f}, material::kTrim);
  // Rear-view mirror on a short stem up to the glass, inside it: the windshield pass draws the
  // water over whatever lies beyond the glass.
  m.add_box({1.50f, -0.09f, 1.22f}, {1.52f, 0.09f, 1.27f}, material::kBody);
  m.add_box({1.47f, -0.012f, 1.27f}, {1.49f, 0.012f, 1.32f}, material::kTrim);
  return m;
}

}  // namespace downpour::render
