// The built-in track exported as OpenDRIVE by the project's own code and read back by its own
// parser: the same road to a centimetre, every metre of the loop.
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "server/road/opendrive.hpp"
#include "server/sim/track.hpp"
#include "server/sim/track_opendrive.hpp"

namespace downpour::sim {
namespace {

TEST(TrackOpenDrive, ReadsBackAsTheTrackToACentimetre) {
  const Track& track = Track::built_in();
  const road::Network net = road::parse_opendrive(track_to_opendrive(track));
  ASSERT_EQ(net.roads.size(), 1u);
  const road::Road& road = net.roads[0];
  EXPECT_NEAR(road.length, track.length(), 1e-6);
  EXPECT_EQ(road.successor.id, "1") << "the loop closes on itself";
  const CrossSection& c = track.cross_section();
  double worst_xy = 0.0, worst_z = 0.0, worst_heading = 0.0;
  for (double s = 0.0; s < track.length(); s += 1.0) {
    const TrackFrame f = track.at(s);
    const road::RefPoint p = road.reference(s);
    worst_xy = std::max(worst_xy, std::hypot(p.x - f.position.x, p.y - f.position.y));
    const double dh = std::remainder(p.heading - f.heading_rad, 2.0 * std::numbers::pi);
    worst_heading = std::max(worst_heading, std::abs(dh));
    // The surface across the road: lanes, the crown, the shoulders and beyond.
    for (const double t : {0.0, 1.0, -2.0, 3.5, -5.2, 7.9, -8.5, 10.0}) {
      worst_z = std::max(worst_z, std::abs(road.surface_height(s, t) - track.surface_height(s, t)));
    }
  }
  std::printf("over %.0f m: xy within %.2g m, heading %.2g rad, surface height %.2g m\n",
              track.length(), worst_xy, worst_heading, worst_z);
  EXPECT_LT(worst_xy, 1e-6) << "the issue asks for 1 cm; the file's 12 digits give far better";
  EXPECT_LT(worst_heading, 1e-9);
  EXPECT_LT(worst_z, 1e-5) << "the hill's cubic pieces every 10 m";
  // The lanes: the track's lane centres are the file's lane middles, right of the reference line
  // in the direction of travel.
  for (int lane = 0; lane < c.lanes_each_way; ++lane) {
    const double middle =
        0.5 * (road.lane_border(100.0, -lane) + road.lane_border(100.0, -lane - 1));
    EXPECT_NEAR(middle, track.lane_centre(lane), 1e-9);
  }
  EXPECT_NEAR(road.lane_border(100.0, -(c.lanes_each_way + 1)), -track.paved_half_width(), 1e-9);
  const road::LaneSection& section = road.sections[0];
  EXPECT_EQ(section.right.back().type, "shoulder");
  EXPECT_EQ(section.centre.marks.at(0).type, "solid solid");
  EXPECT_EQ(section.right[0].marks.at(0).type, "broken");
}

}  // namespace
}  // namespace downpour::sim
