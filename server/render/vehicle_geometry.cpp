#include "server/render/vehicle_geometry.hpp"

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>

#include "server/sim/car_body.hpp"

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
