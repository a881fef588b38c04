// The road's meshes built from an OpenDRIVE network: lane sections whose lanes differ in number
// give each its own mesh, whole and indexed within its vertices; the coarser levels' verges reach
// as far and as low on fewer stations; a narrow one-sided road's relief is made without a bowl out
// of its room. The terrain's chunks meet without a crack where two are drawn at one level, so that
// their skirts are needed only where the levels differ.
#include "server/render/cpu/scene_geometry.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

#include "server/sim/opendrive_roads.hpp"
#include "server/sim/road_surface.hpp"

namespace downpour::render {
namespace {

std::string lane(int id, double width) {
  return "<lane id=\"" + std::to_string(id) + "\" type=\"driving\"><width sOffset=\"0\" a=\"" +
         std::to_string(width) +
         "\" b=\"0\" c=\"0\" d=\"0\"/><roadMark sOffset=\"0\" type=\"broken\" width=\"0.12\"/>"
         "</lane>";
}

// A 200 m road: one lane each way for 80 m, then three to the right and none to the left; and a
// one-way road of a single 2.5 m lane.
const char* const kHeader = R"(<OpenDRIVE><header revMajor="1" revMinor="6"/>)";
std::string network() {
  return std::string(kHeader) + R"(<road id="a" length="200" junction="-1">
    <planView><geometry s="0" x="0" y="0" hdg="0" length="200"><line/></geometry></planView>
    <lanes><laneSection s="0"><left>)" +
         lane(1, 3.5) + R"(</left><center><lane id="0" type="none"/></center><right>)" +
         lane(-1, 3.5) + R"(</right></laneSection>
      <laneSection s="80"><center><lane id="0" type="none"/></center><right>)" +
         lane(-1, 3.5) + lane(-2, 3.5) + lane(-3, 3.0) + R"(</right></laneSection></lanes>
  </road>
  <road id="b" length="60" junction="-1">
    <planView><geometry s="0" x="0" y="100" hdg="0" length="60"><line/></geometry></planView>
    <lanes><laneSection s="0"><center><lane id="0" type="none"/></center><right>)" +
         lane(-1, 2.5) + R"(</right></laneSection></lanes>
  </road></OpenDRIVE>)";
}

TEST(SceneGeometryTest, LaneSectionsOfDifferentLanesMakeWholeMeshes) {
  const auto roads = std::make_shared<const sim::OpenDriveRoads>(road::parse_opendrive(network()));
  const std::vector<std::vector<MeshData>> chunks = build_road_chunks(*roads);
  ASSERT_FALSE(chunks.empty());
  std::size_t triangles = 0;
  for (const std::vector<MeshData>& levels : chunks) {
    ASSERT_EQ(levels.size(), 3u);
    for (const MeshData& m : levels) {
      ASSERT_EQ(m.lanes.size(), m.vertices.size());
      ASSERT_EQ(m.curvature.size(), m.vertices.size());
      ASSERT_EQ(m.indices.size() % 3, 0u);
      for (const std::uint32_t i : m.indices) ASSERT_LT(i, m.vertices.size());
      triangles += m.indices.size() / 3;
    }
  }
  EXPECT_GT(triangles, 0u);
  // The second section's mesh reaches 10 m right of the reference line (three lanes), the
  // first's 3.5 m either side.
  float rightmost = 0.0f, leftmost = 0.0f;
  for (const std::vector<MeshData>& levels : chunks) {
    for (const MeshVertex& v : levels[0].vertices) {
      if (v.position.y > 50.0f) continue;  // road b
      if (v.uv.y < 79.0f) leftmost = std::max(leftmost, v.uv.x);
      if (v.uv.y > 81.0f) rightmost = std::min(rightmost, v.uv.x);
    }
  }
  EXPECT_NEAR(leftmost, 3.5f + 4.0f, 1e-3) << "the left lane and its verge";
  EXPECT_NEAR(rightmost, -10.0f - 4.0f, 1e-3) << "three lanes and the verge";
  // The narrow road has no room for bowls beside its crown, and its relief is still sound.
  const sim::RoadSurface surface(roads, 3);
  for (double s = 0.0; s < 60.0; s += 0.5) {
    for (double t = -2.5; t <= 0.0; t += 0.25) {
      const double r = surface.relief({1, s, t});
      ASSERT_LE(r, 0.0);
      ASSERT_GT(r, -0.05);
    }
  }
}

TEST(SceneGeometryTest, TheCoarserLevelsVergesReachAsFarOnFewerStations) {
  const auto roads = std::make_shared<const sim::OpenDriveRoads>(road::parse_opendrive(network()));
  const std::vector<std::vector<MeshData>> chunks = build_road_chunks(*roads);
  ASSERT_FALSE(chunks.empty());
  for (const std::vector<MeshData>& levels : chunks) {
    // Each level's columns (lateral offsets: stations and lane borders) and its lowest point.
    auto columns = [](const MeshData& m) {
      std::vector<float> t;
      for (const MeshVertex& v : m.vertices) t.push_back(v.uv.x);
      std::sort(t.begin(), t.end());
      t.erase(
          std::unique(t.begin(), t.end(), [](float a, float b) { return std::abs(a - b) < 1e-4f; }),
          t.end());
      return t;
    };
    auto lowest = [](const MeshData& m) {
      float z = 1e30f;
      for (const MeshVertex& v : m.vertices) z = std::min(z, v.position.z);
      return z;
    };
    const std::vector<float> fine = columns(levels[0]);
    for (std::size_t l = 1; l < levels.size(); ++l) {
      const std::vector<float> coarse = columns(levels[l]);
      // Two stations fewer on each verge (its edge, then every 2 m, not every metre). (This
      // network's verges are all open, no other road's pavement beyond them, and its lanes keep
      // their widths: each lateral offset a column.)
      EXPECT_EQ(coarse.size() + 4, fine.size()) << "level " << l;
      EXPECT_NEAR(coarse.front(), fine.front(), 1e-4f);
      EXPECT_NEAR(coarse.back(), fine.back(), 1e-4f);
      EXPECT_NEAR(lowest(levels[l]), lowest(levels[0]), 1e-3f);
    }
  }
}

// The terrain chunk's vertices on edge `e` (south, north, west, east), sorted.
std::vector<std::tuple<float, float, float>> edge_vertices(const MeshData& surface, int e) {
  const int axis = e < 2 ? 1 : 0;  // south and north lie along y = const
  const float line = e % 2 == 0 ? surface.bounds_min[axis] : surface.bounds_max[axis];
  std::vector<std::tuple<float, float, float>> out;
  for (const MeshVertex& v : surface.vertices) {
    if (v.position[axis] == line) out.emplace_back(v.position.x, v.position.y, v.position.z);
  }
  std::sort(out.begin(), out.end());
  return out;
}

TEST(SceneGeometryTest, TerrainChunksAtOneLevelShareTheirEdges) {
  const auto roads = std::make_shared<const sim::OpenDriveRoads>(road::parse_opendrive(network()));
  const SkirtedChunks terrain = build_terrain_chunks(*roads);
  ASSERT_EQ(terrain.levels.size(), 256u);
  ASSERT_EQ(terrain.skirts.size(), terrain.levels.size());
  ASSERT_EQ(terrain.across.size(), terrain.levels.size());
  int borders = 0, finer_edges = 0;
  for (std::size_t c = 0; c < terrain.levels.size(); ++c) {
    ASSERT_EQ(terrain.levels[c].size(), 4u);
    ASSERT_EQ(terrain.skirts[c].size(), 4u);
    for (int e = 0; e < 4; ++e) {
      const int n = terrain.across[c][e];
      if (n < 0) {
        ++borders;
        continue;
      }
      ASSERT_LT(n, static_cast<int>(terrain.levels.size()));
      EXPECT_EQ(terrain.across[n][e ^ 1], static_cast<int>(c)) << "neighbours both ways";
      for (int k = 0; k < 4; ++k) {
        // The same vertices, bit for bit, on both sides of the edge: no crack at one level.
        const auto mine = edge_vertices(terrain.levels[c][k], e);
        ASSERT_GE(mine.size(), 2u);
        EXPECT_EQ(mine, edge_vertices(terrain.levels[n][k], e ^ 1)) << c << " " << e << " " << k;
        // The skirt hangs from those vertices: its upper vertices are they, its lower ones lie
        // below them.
        const MeshData& skirt = terrain.skirts[c][k][e];
        EXPECT_EQ(skirt.indices.size(), (mine.size() - 1) * 6);
        std::vector<std::tuple<float, float, float>> upper;
        int below = 0;
        for (const MeshVertex& v : skirt.vertices) {
          const std::tuple<float, float, float> p(v.position.x, v.position.y, v.position.z);
          if (std::binary_search(mine.begin(), mine.end(), p)) {
            upper.push_back(p);
          } else {
            below += std::any_of(mine.begin(), mine.end(), [&](const auto& m) {
              return std::get<0>(m) == v.position.x && std::get<1>(m) == v.position.y &&
                     std::get<2>(m) > v.position.z + 1.0f;
            });
          }
        }
        std::sort(upper.begin(), upper.end());
        upper.erase(std::unique(upper.begin(), upper.end()), upper.end());
        EXPECT_EQ(upper, mine) << c << " " << e << " " << k;
        EXPECT_EQ(below * 2, static_cast<int>(skirt.vertices.size()));
        if (k > 0) finer_edges += edge_vertices(terrain.levels[c][k - 1], e).size() > mine.size();
      }
    }
  }
  EXPECT_EQ(borders, 4 * 16) << "the border's chunks have no neighbour outside";
  // A finer level's edge has vertices the coarser lacks, which is where a crack opens.
  EXPECT_GT(finer_edges, 0);
}

}  // namespace
}  // namespace downpour::render
