// The visible road's states from the view's rays: all dry on a dry road, mostly drench under a
// film with the puddles counted, adding up to 1 where the road is in sight; a puddle under a car
// is not seen; nothing in the views that see no road.
#include "server/render/cpu/view_road_states.hpp"

#include <chrono>
#include <cstdio>

#include <gtest/gtest.h>

#include "server/sim/pose.hpp"
#include "server/sim/scenario.hpp"
#include "tests/render/road_water_fixture.hpp"

namespace downpour::render {
namespace {

sim::SceneState scene_with_road(double film_mm, bool puddles) {
  sim::SceneState s;
  s.vehicle = *sim::highway_heavy_rain().at(10.0).vehicle;
  s.road_water = testing::hand_road_water(
      s.vehicle, film_mm, puddles ? testing::test_puddles() : std::vector<testing::HandPuddle>{});
  return s;
}

double sum(const RoadStateFractions& f) { return f.dry + f.wet + f.drench + f.puddle; }

TEST(ViewRoadStatesTest, ADryRoadIsAllDry) {
  const RoadStateFractions f =
      view_road_states(sim::view_spec(sim::View::kRoad, 640, 360), scene_with_road(0.0, false));
  EXPECT_DOUBLE_EQ(f.dry, 1.0);
}

TEST(ViewRoadStatesTest, AFilmIsDrenchAndThePuddlesAreCounted) {
  const sim::SceneState scene = scene_with_road(0.3, true);
  for (const sim::View view : {sim::View::kRoad, sim::View::kCockpit}) {
    const auto t0 = std::chrono::steady_clock::now();
    const RoadStateFractions f = view_road_states(sim::view_spec(view, 640, 360), scene);
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    std::printf("%s: dry %.3f wet %.3f drench %.3f puddle %.3f (%.2f ms)\n",
                std::string(sim::view_name(view)).c_str(), f.dry, f.wet, f.drench, f.puddle, ms);
    EXPECT_NEAR(sum(f), 1.0, 1e-9);
    EXPECT_GT(f.drench, 0.5);
    EXPECT_GT(f.puddle, 0.0);
    EXPECT_EQ(f.dry, 0.0);
  }
}

TEST(ViewRoadStatesTest, AVehicleHidesThePuddleUnderIt) {
  // A puddle 12 m ahead in the driver's lane, on an otherwise dry road: seen from the driver's
  // seat, then hidden under a car stopped over it.
  sim::SceneState scene;
  scene.vehicle = *sim::highway_heavy_rain().at(10.0).vehicle;
  scene.road_water = testing::hand_road_water(scene.vehicle, 0.0, {{12.0, 0.0, 1.2, 6.0}});
  const sim::ViewSpec spec = sim::view_spec(sim::View::kCockpit, 640, 360);
  const RoadStateFractions open = view_road_states(spec, scene);
  sim::TrafficVehicle ahead;
  ahead.state = scene.vehicle;
  const glm::dmat4 to_world = sim::vehicle_to_world(scene.vehicle);
  ahead.state.position_m = glm::dvec3(to_world * glm::dvec4(10.0, 0.0, 0.0, 1.0));
  scene.traffic.push_back(ahead);
  const RoadStateFractions hidden = view_road_states(spec, scene);
  std::printf("the puddle's share of the road in sight: %.4f open, %.4f under the car\n",
              open.puddle, hidden.puddle);
  EXPECT_GT(open.puddle, 0.005);
  EXPECT_EQ(hidden.puddle, 0.0);
  EXPECT_NEAR(sum(hidden), 1.0, 1e-9);
}

TEST(ViewRoadStatesTest, ViewsWithoutRoadSeeNone) {
  const sim::SceneState scene = scene_with_road(0.3, true);
  for (const sim::View view : {sim::View::kWindshield, sim::View::kRain})
    EXPECT_EQ(sum(view_road_states(sim::view_spec(view, 640, 360), scene)), 0.0);
}

}  // namespace
}  // namespace downpour::render
