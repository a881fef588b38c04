// The cabin's tiles in the driver's view, from its mesh on the CPU: the dashboard's and the roof's
// are hidden, the road's ahead through the glass is clear, and between them lie edge tiles.
#include "server/render/cpu/cabin_tiles.hpp"

#include <cstdio>
#include <utility>

#include <gtest/gtest.h>

#include "server/model/default_models.hpp"
#include "server/sim/types.hpp"

namespace downpour::render {
namespace {

TEST(CabinTilesTest, TheDashboardAndRoofAreHiddenTheRoadAheadClearWithEdgesBetween) {
  constexpr int kWidth = 320, kHeight = 180, kTile = 8;  // the rain layer of a 640x360 view
  const sim::ViewSpec spec = sim::view_spec(sim::View::kCockpit, 640, 360);
  const Camera camera = make_camera(spec, sim::VehicleState{});
  const sim::GlassConfig glass;
  const std::vector<std::uint8_t> hidden =
      cabin_tiles(model::default_cabin(glass).mesh, camera, kWidth, kHeight, kTile);
  const int tiles_x = kWidth / kTile, tiles_y = (kHeight + kTile - 1) / kTile;
  ASSERT_EQ(hidden.size(), static_cast<std::size_t>(tiles_x * tiles_y));
  auto at = [&](int tx, int ty) { return hidden[ty * tiles_x + tx]; };  // rows bottom-up
  EXPECT_EQ(at(tiles_x / 2, 0), kCabinHidden) << "the dashboard, bottom centre";
  EXPECT_EQ(at(tiles_x / 2, tiles_y - 1), kCabinHidden) << "the roof, top centre";
  EXPECT_EQ(at(tiles_x / 2, tiles_y / 2), kCabinClear) << "the road ahead, through the glass";
  // Up the middle column from the road to the roof: clear, then edge tiles, then hidden, with no
  // clear tile beside a hidden one (an edge tile lies between).
  int count = 0, edges = 0;
  for (std::uint8_t h : hidden) count += h == kCabinHidden, edges += h == kCabinEdge;
  for (int ty = 0; ty < tiles_y; ++ty) {
    for (int tx = 0; tx < tiles_x; ++tx) {
      if (at(tx, ty) != kCabinClear) continue;
      for (const auto& [dx, dy] : {std::pair{-1, 0}, {1, 0}, {0, -1}, {0, 1}}) {
        const int x = tx + dx, y = ty + dy;
        if (x < 0 || y < 0 || x >= tiles_x || y >= tiles_y) continue;
        EXPECT_NE(at(x, y), kCabinHidden)
            << "a clear tile beside a hidden one at " << tx << ", " << ty;
      }
    }
  }
  std::printf("hidden: %d, edge: %d of %zu tiles\n", count, edges, hidden.size());
  EXPECT_GT(edges, 0);
  EXPECT_LT(edges, count);
  EXPECT_GT(count, static_cast<int>(hidden.size()) / 5);
  EXPECT_LT(count, static_cast<int>(hidden.size()) * 3 / 5);
}

}  // namespace
}  // namespace downpour::render
