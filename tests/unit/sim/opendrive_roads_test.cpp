// An OpenDRIVE network as the roads a session drives on: world positions found on the right road
// at the right (s, t), heights with elevation and superelevation, lanes and marks across, the
// road's relief on each lane section, street lights beside the roads and never on one.
#include <cmath>
#include <numbers>
#include <string>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include "server/sim/lights.hpp"
#include "server/sim/opendrive_roads.hpp"
#include "server/sim/road_surface.hpp"

namespace downpour::sim {
namespace {

constexpr double kPi = std::numbers::pi;

// A straight road along +x rising 1% with a 0.02 rad roll, an arc of 50 m radius after it (a
// quarter turn left), and a level road crossing the straight at x = 50.
std::string three_roads() {
  const std::string lanes = R"(
      <lanes><laneSection s="0">
        <left><lane id="1" type="driving"><width sOffset="0" a="3.5" b="0" c="0" d="0"/>
          <roadMark sOffset="0" type="solid" color="standard" width="0.15"/></lane></left>
        <center><lane id="0" type="none">
          <roadMark sOffset="0" type="solid solid" color="yellow" width="0.12"/></lane></center>
        <right>
          <lane id="-1" type="driving"><width sOffset="0" a="3.5" b="0" c="0" d="0"/>
            <roadMark sOffset="0" type="broken" color="standard" width="0.15"/></lane>
          <lane id="-2" type="shoulder"><width sOffset="0" a="1.5" b="0" c="0" d="0"/>
            <roadMark sOffset="0" type="solid" color="white" width="0.2"/></lane>
        </right>
      </laneSection></lanes>)";
  return R"(<?xml version="1.0"?>
<OpenDRIVE><header revMajor="1" revMinor="6" name="three roads"/>
  <road id="1" length="100" junction="-1">
    <planView><geometry s="0" x="0" y="0" hdg="0" length="100"><line/></geometry></planView>
    <elevationProfile><elevation s="0" a="2" b="0.01" c="0" d="0"/></elevationProfile>
    <lateralProfile><superelevation s="0" a="0.02" b="0" c="0" d="0"/></lateralProfile>)" +
         lanes + R"(
  </road>
  <road id="2" length="78.53981633974483" junction="-1">
    <planView><geometry s="0" x="100" y="0" hdg="0" length="78.53981633974483">
      <arc curvature="0.02"/></geometry></planView>)" +
         lanes + R"(
  </road>
  <road id="3" length="80" junction="-1">
    <planView><geometry s="0" x="50" y="-40" hdg="1.5707963267948966" length="80"><line/>
    </geometry></planView>)" +
         lanes + R"(
  </road>
</OpenDRIVE>)";
}

class OpenDriveRoadsTest : public ::testing::Test {
 protected:
  std::shared_ptr<const OpenDriveRoads> roads =
      std::make_shared<const OpenDriveRoads>(road::parse_opendrive(three_roads()));
};

TEST_F(OpenDriveRoadsTest, PositionsFindTheirRoadAndPlace) {
  // On the straight, away from the crossing: (s, t) exactly, on road 0.
  for (const double s : {5.0, 30.0, 80.0, 99.0}) {
    for (const double t : {-4.9, -1.0, 0.0, 2.5}) {
      const RoadPlace p = roads->project({s, t});
      EXPECT_EQ(p.road, 0) << s << " " << t;
      EXPECT_NEAR(p.s, s, 1e-6);
      EXPECT_NEAR(p.t, t, 1e-6);
      // 2 m + 1% up, the left side higher by the roll.
      EXPECT_NEAR(roads->surface_height(p), 2.0 + 0.01 * s + t * std::tan(0.02), 1e-9);
    }
  }
  // On the arc: centre (100, 50), radius 50; s = 50 theta, t inwards positive.
  for (const double theta : {0.2, 0.7, 1.3}) {
    for (const double t : {-3.0, 1.0}) {
      const glm::dvec2 xy =
          glm::dvec2(100.0, 50.0) + (50.0 - t) * glm::dvec2(std::sin(theta), -std::cos(theta));
      const RoadPlace p = roads->project(xy);
      EXPECT_EQ(p.road, 1);
      EXPECT_NEAR(p.s, 50.0 * theta, 1e-6);
      EXPECT_NEAR(p.t, t, 1e-6);
    }
  }
  // Where the straight and the crossing road overlap, either holds the point on its pavement.
  const RoadPlace crossing = roads->project({50.5, 0.5});
  EXPECT_NE(crossing.road, 1);
  EXPECT_TRUE(roads->paved(crossing.road, crossing.s).contains(crossing.t));
  EXPECT_EQ(roads->off_road({50.5, 0.5}, crossing), 0.0);
  // Off every road: the nearest edge's road, the distance to it.
  const RoadPlace field = roads->project({20.0, 15.0});
  EXPECT_EQ(field.road, 0);
  EXPECT_NEAR(field.t, 15.0, 1e-6);
  EXPECT_NEAR(roads->off_road({20.0, 15.0}, field), 11.5, 1e-6);
  // Past a road's end: how far past it counts.
  EXPECT_NEAR(roads->off_road({-3.0, 0.0}, roads->project({-3.0, 0.0})), 3.0, 1e-6);
  // From a neighbour's place: the same answer.
  const RoadPlace near = roads->project_near({31.0, -2.0}, {0, 29.0, -1.0});
  EXPECT_EQ(near.road, 0);
  EXPECT_NEAR(near.s, 31.0, 1e-9);
  EXPECT_NEAR(near.t, -2.0, 1e-9);
  // A guess on the wrong road: the search finds the right one.
  const RoadPlace moved = roads->project_near({60.0, 25.0}, {0, 60.0, 0.0});
  EXPECT_EQ(moved.road, 2);
  EXPECT_NEAR(moved.s, 65.0, 1e-6);
}

TEST_F(OpenDriveRoadsTest, FramesAndLanesAreTheFilesOwn) {
  const TrackFrame f = roads->frame(1, 12.5 * kPi);  // half way round the quarter turn
  EXPECT_NEAR(f.heading_rad, kPi / 4.0, 1e-9);
  EXPECT_NEAR(f.position.x, 100.0 + 50.0 * std::sin(kPi / 4.0), 1e-6);
  EXPECT_NEAR(roads->frame(0, 40.0).grade, 0.01, 1e-12);
  EXPECT_NEAR(roads->frame(0, 40.0).position.z, 2.4, 1e-12);

  const LaneLayout lanes = roads->lanes(0, 10.0);
  ASSERT_EQ(lanes.borders.size(), 4u);
  EXPECT_EQ(lanes.centre, 2);
  EXPECT_NEAR(lanes.borders[0], -5.0, 1e-12);
  EXPECT_NEAR(lanes.borders[1], -3.5, 1e-12);
  EXPECT_NEAR(lanes.borders[3], 3.5, 1e-12);
  EXPECT_EQ(lanes.driving, (std::vector<std::uint8_t>{0, 1, 1}));
  EXPECT_EQ(lanes.marks[0].kind, LaneMark::Kind::kSolid);
  EXPECT_NEAR(lanes.marks[0].width_m, 0.2, 1e-12);
  EXPECT_EQ(lanes.marks[1].kind, LaneMark::Kind::kBroken);
  EXPECT_EQ(lanes.marks[2].kind, LaneMark::Kind::kSolidSolid);
  EXPECT_TRUE(lanes.marks[2].yellow);
  EXPECT_FALSE(lanes.marks[3].yellow);
  const PavedSpan span = roads->paved(0, 10.0);
  EXPECT_NEAR(span.right, -5.0, 1e-12);
  EXPECT_NEAR(span.left, 3.5, 1e-12);
  // Beyond the paved width, its edge's height.
  EXPECT_NEAR(roads->surface_height({0, 10.0, 9.0}), roads->surface_height({0, 10.0, 3.5}), 1e-12);
}

TEST_F(OpenDriveRoadsTest, AnEgoPlaceNamesItsRoadAndLane) {
  const EgoPlace inner = ego_place(*roads, {30.0, -1.75});
  EXPECT_EQ(inner.road, "1");
  EXPECT_NEAR(inner.s_m, 30.0, 1e-6);
  EXPECT_EQ(inner.lane, -1);
  EXPECT_NEAR(inner.lane_offset_m, 0.0, 1e-6);
  EXPECT_TRUE(inner.on_road);
  const EgoPlace left = ego_place(*roads, {30.0, 2.0});
  EXPECT_EQ(left.lane, 1);
  EXPECT_NEAR(left.lane_offset_m, 0.25, 1e-6);
  const EgoPlace shoulder = ego_place(*roads, {30.0, -4.5});
  EXPECT_EQ(shoulder.lane, -2);
  EXPECT_NEAR(shoulder.lane_offset_m, -0.25, 1e-6);
  const EgoPlace off = ego_place(*roads, {30.0, -9.0});
  EXPECT_FALSE(off.on_road);
  EXPECT_EQ(off.lane, -2) << "beyond the edge: the outermost lane";
  // The built-in track: lane -2 is its outer lane, driving forwards.
  const Track& track = Track::built_in();
  const TrackFrame f = track.at(500.0);
  const EgoPlace on_track =
      ego_place(*built_in_roads(), glm::dvec2(f.position) + f.left * track.lane_centre(1));
  EXPECT_EQ(on_track.road, "track");
  EXPECT_EQ(on_track.lane, -2);
  EXPECT_NEAR(on_track.lane_offset_m, 0.0, 0.01);
}

TEST_F(OpenDriveRoadsTest, TheReliefLiesInTheDrivenLanesWheelPathsAndRepeatsWithTheSeed) {
  const RoadSurface surface(roads, 11);
  const RoadSurface again(roads, 11);
  const RoadSurface other(roads, 12);
  double deepest_rut = 0.0, beside = 0.0;
  int differ = 0;
  for (int road = 0; road < 3; ++road) {
    for (double s = 1.0; s < roads->road_length(road); s += 1.7) {
      for (double t = -8.0; t <= 6.0; t += 0.25) {
        const RoadPlace p{road, s, t};
        const double r = surface.relief(p);
        ASSERT_EQ(r, again.relief(p));
        differ += r != other.relief(p);
        if (!roads->paved(road, s).contains(t)) {
          ASSERT_EQ(r, 0.0) << road << " " << s << " " << t;
          continue;
        }
        ASSERT_LE(r, 0.0);
        ASSERT_GE(r, -0.05);
      }
      // The wheel paths of lane -1 (centre -1.75) and lane 1 (1.75), 0.8 m either side.
      for (const double path : {-2.55, -0.95, 0.95, 2.55}) {
        deepest_rut = std::min(deepest_rut, surface.relief({road, s, path}));
      }
      beside = std::min(beside, surface.relief({road, s, -4.25}));  // the shoulder's middle
    }
  }
  EXPECT_LT(deepest_rut, -RoadSurface::kRutMinDepthM);
  EXPECT_GT(differ, 100) << "another seed, another relief";
  // Heights from world positions: the section plus the relief.
  const glm::dvec2 xy(30.0, -2.0);
  EXPECT_NEAR(surface.height(xy),
              roads->surface_height({0, 30.0, -2.0}) + surface.relief({0, 30.0, -2.0}), 1e-9);
}

TEST_F(OpenDriveRoadsTest, StreetLightsStandBesideTheRoadsNeverOnOne) {
  const std::vector<StreetLight> lights = street_lights(*roads);
  int on_road[3] = {0, 0, 0};
  for (const StreetLight& l : lights) {
    ++on_road[l.road];
    const RoadPlace under = roads->project(glm::dvec2(l.foot_m));
    EXPECT_GT(roads->off_road(glm::dvec2(l.foot_m), under), 0.5)
        << "a pole on road " << under.road << " at s " << under.s;
    EXPECT_GT(l.lamp_m.z, l.foot_m.z + 8.0);
  }
  // One every 25 m, less those that would stand on the crossing road.
  EXPECT_GE(on_road[0], 3);
  EXPECT_EQ(on_road[1], 3);
  EXPECT_GE(on_road[2], 2);
}

}  // namespace
}  // namespace downpour::sim
