// The cabin's tiles in the driver's view, from its mesh on the CPU: the dashboard's and the roof's
// are hidden, the road's ahead through the glass is not.
#include "server/render/cabin_tiles.hpp"

#include <cstdio>

#include <gtest/gtest.h>

#include "server/render/vehicle_geometry.hpp"
#include "server/sim/types.hpp"

namespace downpour::render {
namespace {

TEST(CabinTilesTest, TheDashboardAndRoofAreHiddenAndTheRoadAheadIsNot) {
  constexpr int kWidth = 320, kHeight = 180, kTile = 8;  // the rain layer of a 640x360 view
  const sim::ViewSpec spec = sim::view_spec(sim::View::kCockpit, 640, 360);
  const Camera camera = make_camera(spec, sim::VehicleState{});
  const sim::GlassConfig glass;
  const std::vector<std::uint8_t> hidden =
      cabin_tiles(build_cockpit_interior(glass), camera, kWidth, kHeight, kTile);
  const int tiles_x = kWidth / kTile, tiles_y = (kHeight + kTile - 1) / kTile;
  ASSERT_EQ(hidden.size(), static_cast<std::size_t>(tiles_x * tiles_y));
  auto at = [&](int tx, int ty) { return hidden[ty * tiles_x + tx]; };  // rows bottom-up
  EXPECT_TRUE(at(tiles_x / 2, 0)) << "the dashboard, bottom centre";
  EXPECT_TRUE(at(tiles_x / 2, tiles_y - 1)) << "the roof, top centre";
  EXPECT_FALSE(at(tiles_x / 2, tiles_y / 2)) << "the road ahead, through the glass";
  int count = 0;
  for (std::uint8_t h : hidden) count += h;
  std::printf("hidden: %d of %zu tiles\n", count, hidden.size());
  EXPECT_GT(count, static_cast<int>(hidden.size()) / 5);
  EXPECT_LT(count, static_cast<int>(hidden.size()) * 3 / 5);
}

}  // namespace
}  // namespace downpour::render
