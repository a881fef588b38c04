#include "server/render/cpu/view_road_states.hpp"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/mat4x4.hpp>

#include "server/render/cpu/camera.hpp"
#include "server/sim/car_body.hpp"
#include "server/sim/pose.hpp"
#include "server/sim/road_network.hpp"

namespace downpour::render {

namespace {

constexpr double kFarM = 300.0;

// A box in a vehicle's frame (its body down to the road), with the world-to-frame transform.
struct Box {
  glm::dmat4 to_local;
  glm::dvec3 lo, hi;
};

// Where the ray eye + t dir (world) enters the box, or a huge value where it misses it.
double enters(const Box& box, const glm::dvec3& eye, const glm::dvec3& dir) {
  const glm::dvec3 o(box.to_local * glm::dvec4(eye, 1.0));
  const glm::dvec3 d(box.to_local * glm::dvec4(dir, 0.0));  // (t keeps its meaning)
  double t0 = 0.0, t1 = 1e300;
  for (int k = 0; k < 3; ++k) {
    if (std::abs(d[k]) < 1e-12) {
      if (o[k] < box.lo[k] || o[k] > box.hi[k]) return 1e300;
      continue;
    }
    double a = (box.lo[k] - o[k]) / d[k], b = (box.hi[k] - o[k]) / d[k];
    if (a > b) std::swap(a, b);
    t0 = std::max(t0, a);
    t1 = std::min(t1, b);
    if (t0 > t1) return 1e300;
  }
  return t0;
}

// The boxes that hide the road: the ego car's hull (from the driver's seat, only the bonnet ahead
// of the glass; from outside, the whole car), and each traffic vehicle's body, scaled to its size
// as the vehicle pass draws it.
std::vector<Box> occluders(const sim::ViewSpec& spec, const sim::SceneState& scene) {
  namespace body = sim::car_body;
  std::vector<Box> boxes;
  const glm::dvec3 hull_lo(body::kHullRearX, -body::kHullHalfWidth, 0.0);
  const glm::dvec3 hull_hi(body::kHullFrontX, body::kHullHalfWidth, body::kHullTopZ);
  auto add_car = [&](const glm::dmat4& to_world) {
    const glm::dmat4 to_local = glm::inverse(to_world);
    boxes.push_back({to_local, hull_lo, hull_hi});
    boxes.push_back({to_local, glm::dvec3(body::kCabinRearX, -body::kCabinHalfWidth, 0.0),
                     glm::dvec3(body::kCabinFrontX, body::kCabinHalfWidth, body::kRoofZ)});
  };
  const glm::dmat4 ego = sim::vehicle_to_world(scene.vehicle);
  if (spec.view == sim::View::kCockpit) {
    boxes.push_back({glm::inverse(ego), glm::dvec3(body::kCabinFrontX, hull_lo.y, 0.0), hull_hi});
  } else {
    add_car(ego);
  }
  for (const sim::TrafficVehicle& other : scene.traffic) {
    const glm::dvec3 scale(other.size_m.x / 4.6, other.size_m.y / 1.8, other.size_m.z / 1.47);
    add_car(glm::scale(sim::vehicle_to_world(other.state), scale));
  }
  return boxes;
}

}  // namespace

RoadStateFractions view_road_states(const sim::ViewSpec& spec, const sim::SceneState& scene) {
  RoadStateFractions out;
  if ((spec.view != sim::View::kCockpit && spec.view != sim::View::kRoad) || spec.width <= 0 ||
      spec.height <= 0) {
    return out;
  }
  const sim::RoadWaterImage* image = scene.road_water.get();
  const sim::RoadNetwork& roads = scene.roads ? *scene.roads : *sim::built_in_roads();
  const Camera camera = make_camera(spec, scene.vehicle, &scene.weather);
  const glm::dmat4 inverse = glm::inverse(glm::dmat4(camera.projection * camera.view));
  const glm::dvec3 eye(camera.position);
  // The road's plane under the car: its height there, level (the correction below adds the rest).
  const glm::dvec2 car(scene.vehicle.position_m);
  const sim::RoadPlace under = roads.project(car, 50.0);
  const double ground = roads.surface_height(under);
  sim::RoadWaterConfig thresholds;
  if (image) thresholds.capacity_m = image->capacity_mm * 1e-3;
  constexpr int kColumns = 64, kRows = 36;
  const std::vector<Box> boxes = occluders(spec, scene);
  int counts[4] = {0, 0, 0, 0};
  for (int row = 0; row < kRows; ++row) {
    // Neighbouring rays land near each other: each one's place on the roads starts from the last
    // one's (a few Newton steps), the first of a row from the car's.
    sim::RoadPlace guess = under;
    for (int col = 0; col < kColumns; ++col) {
      const glm::dvec4 p = inverse * glm::dvec4((col + 0.5) / kColumns * 2.0 - 1.0,
                                                1.0 - (row + 0.5) / kRows * 2.0, 0.5, 1.0);
      const glm::dvec3 dir = glm::normalize(glm::dvec3(p) / p.w - eye);
      if (dir.z > -1e-4) continue;  // the sky
      double t = (ground - eye.z) / dir.z;
      if (t <= 0.0 || t > kFarM) continue;
      sim::RoadPlace at = roads.project_near(glm::dvec2(eye + dir * t), guess);
      t = (roads.surface_height(at) - eye.z) / dir.z;
      if (t <= 0.0 || t > kFarM) continue;
      const glm::dvec3 hit = eye + dir * t;
      at = roads.project_near(glm::dvec2(hit), at);
      guess = at;
      if (!roads.paved(at.road, at.s).contains(at.t)) continue;
      bool hidden = false;
      for (const Box& box : boxes) hidden = hidden || enters(box, eye, dir) < t;
      if (hidden) continue;
      double water_mm = 0.0;
      if (image && image->complete()) water_mm = image->at(glm::dvec2(hit)).x;
      // (RoadState's order: dry, wet, drench, puddle.)
      ++counts[static_cast<int>(sim::road_state(water_mm * 1e-3, thresholds))];
    }
  }
  const int total = counts[0] + counts[1] + counts[2] + counts[3];
  if (total == 0) return out;
  out.dry = static_cast<double>(counts[0]) / total;
  out.wet = static_cast<double>(counts[1]) / total;
  out.drench = static_cast<double>(counts[2]) / total;
  out.puddle = static_cast<double>(counts[3]) / total;
  return out;
}

}  // namespace downpour::render
