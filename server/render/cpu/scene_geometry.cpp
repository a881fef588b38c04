#include "server/render/cpu/scene_geometry.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <stdexcept>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "server/render/cpu/mesh_curvature.hpp"
#include "server/render/cpu/shader_interface.hpp"

namespace downpour::render {
namespace {

constexpr double kVerge = 4.0;         // metres of verge beyond the paved edge
constexpr double kVergeDrop = 0.35;    // how far the verge falls below the pavement edge
constexpr double kTerrainCell = 20.0;  // metres
constexpr double kTerrainMargin = 1300.0;
constexpr int kTerrainChunks = 16;  // per axis
constexpr int kTerrainLevels = 4;   // cells of 20, 40, 80 and 160 m
constexpr double kSkirtDepthPerCell = 0.25;
constexpr double kRoadChunkM = 120.0;
constexpr double kRoadStepsM[] = {2.0, 8.0, 24.0};  // cross-sections, near to far

double hills(double x, double y) {
  return 5.0 * std::sin(x / 170.0 + 1.3) * std::cos(y / 210.0 - 0.4) +
         2.5 * std::sin((x + 0.6 * y) / 85.0) + 1.2 * std::cos((0.7 * x - y) / 41.0);
}

}  // namespace

namespace {

// A mark as the road shader reads it (mesh_data.hpp's VertexLane): its centre's offset signed by
// its border's side of the centre lane (side: -1 right, 1 left, 0 the centre).
float mark_attribute(const sim::LaneMark& m, int side) {
  return pack_lane_mark(static_cast<int>(m.kind), m.yellow, m.width_m, side * m.offset_m,
                        m.spacing_m);
}

// The cross-slope (dz/dt) of a road's surface at t, from its heights either side, inward only at
// the paved width's edges.
double cross_slope(const sim::RoadNetwork& roads, int road, double s, double t,
                   const sim::PavedSpan& span) {
  constexpr double e = 0.05;
  const double lo = std::max(t - e, span.right), hi = std::min(t + e, span.left);
  if (hi - lo < 1e-6) return 0.0;
  return (roads.surface_height({road, s, hi}) - roads.surface_height({road, s, lo})) / (hi - lo);
}

// One lane section of a road, [s0, s1), in chunks of chunk_length_m with cross-sections every
// step_m: a column of vertices at every lane border, and a verge beyond each paved edge. Each
// column's flat attributes describe the strip to its left (VertexLane), the provoking vertex of
// both of the strip's triangles.
void road_piece(const sim::RoadNetwork& roads, int road, double s0, double s1,
                double chunk_length_m, double step_m, std::vector<MeshData>& chunks) {
  // The verge's stations: the edge, then every metre; every 2 m at the coarser levels, further
  // off, where fewer triangles are cheaper (chunked_mesh.hpp): the far part of a 640x360 ROAD
  // view's road took 0.62 of the terrain's time, in turn, against 0.69; its picture the same to
  // within 10 levels in a pixel. Where levels meet, the middle stations stand 2 cm off the coarser
  // level's chord: under half a pixel at the nearest such seam, the split of a 640x360 ROAD's
  // road at 17 m.
  const int verge_stations = step_m > kRoadStepsM[0] ? 3 : 5;
  for (double c0 = s0; c0 < s1 - 1e-6; c0 += chunk_length_m) {
    const double c1 = std::min(c0 + chunk_length_m, s1);
    std::vector<double> rows;
    for (double s = c0; s < c1 - 1e-6; s += step_m) rows.push_back(s);
    rows.push_back(c1);
    MeshData m;
    int per_row = 0;
    for (const double s : rows) {
      const sim::TrackFrame f = roads.frame(road, s);
      // The piece's own lanes and heights, at its end too (where the next section's may differ).
      const double se = std::min(s, s1 - 1e-6);
      sim::LaneLayout layout = roads.lanes(road, se);
      // No lines across a junction: its connecting roads overlap, and their marks (which SUMO's
      // netconvert, for one, writes) would draw a tangle of curves over it.
      if (roads.connecting(road)) layout.marks.assign(layout.marks.size(), sim::LaneMark{});
      const sim::PavedSpan span{layout.right(), layout.left()};
      const glm::dvec3 forward(std::cos(f.heading_rad), std::sin(f.heading_rad), f.grade);
      const std::size_t first = m.vertices.size();
      constexpr float kVergeStrip = 1000.0f, kDriving = 100.0f;  // VertexLane's width codes
      auto vertex = [&](double t, double z, double slope, VertexLane lane) {
        const glm::dvec2 xy = glm::dvec2(f.position) + f.left * t;
        const glm::dvec3 side(f.left.x, f.left.y, slope);
        const glm::dvec3 n = glm::normalize(glm::cross(forward, side));
        m.add_vertex(glm::vec3(xy.x, xy.y, z), glm::vec3(n), glm::vec2(t, s));
        m.lanes.push_back(lane);
      };
      // The verges round over from the pavement's edge: level there, falling ever faster. None
      // where another road's pavement lies beyond the edge (the other direction's lanes on a road
      // of one-way halves, a junction): its stations all at the edge, its triangles empty.
      auto verge = [&](double edge, double way) {
        const double z = roads.surface_height({road, se, edge});
        const glm::dvec2 beyond = glm::dvec2(f.position) + f.left * (edge + way * 0.5);
        const sim::RoadPlace other = roads.project(beyond, 30.0);
        const bool covered =
            other.road != road && roads.paved(other.road, other.s).contains(other.t);
        for (int k = 1; k < verge_stations; ++k) {
          const int station = covered ? 0 : way > 0.0 ? k : verge_stations - k;
          const double u = station * (kVerge / (verge_stations - 1)) / kVerge;
          const double slope = -way * 2.0 * kVergeDrop * u / kVerge;
          vertex(edge + way * u * kVerge, z - kVergeDrop * u * u, slope,
                 VertexLane{static_cast<float>(edge), static_cast<float>(way) * kVergeStrip, 0.0f,
                            0.0f});
        }
      };
      verge(span.right, -1.0);
      const int centre = layout.centre;
      for (std::size_t b = 0; b < layout.borders.size(); ++b) {
        const double t = layout.borders[b];
        // (The last border's strip: the left verge.)
        VertexLane attr{static_cast<float>(t), kVergeStrip, 0.0f, 0.0f};
        if (b + 1 < layout.borders.size()) {
          const auto right = static_cast<int>(b), left = right + 1;
          attr.width =
              static_cast<float>(layout.borders[b + 1] - t) + (layout.driving[b] ? kDriving : 0.0f);
          attr.mark_right =
              mark_attribute(layout.marks[right], (right > centre) - (right < centre));
          attr.mark_left = mark_attribute(layout.marks[left], (left > centre) - (left < centre));
        }
        vertex(t, roads.surface_height({road, se, t}), cross_slope(roads, road, se, t, span), attr);
      }
      verge(span.left, 1.0);
      const auto row = static_cast<int>(m.vertices.size() - first);
      if (per_row != 0 && row != per_row) {
        throw std::logic_error("a road piece's rows differ in their columns");
      }
      per_row = row;
    }
    // Each quad's two triangles end on its right column's vertices (OpenGL's provoking vertex is
    // a triangle's last): (i + 1, i + 1 + n, i) and (i + 1 + n, i + n, i), counter-clockwise as
    // (i, i + 1, i + 1 + n, i + n) is.
    for (std::size_t r = 0; r + 1 < rows.size(); ++r) {
      for (int c = 0; c + 1 < per_row; ++c) {
        const auto i = static_cast<std::uint32_t>(r * per_row + c);
        const auto n = static_cast<std::uint32_t>(per_row);
        m.add_triangle(i + 1, i + 1 + n, i);
        m.add_triangle(i + 1 + n, i + n, i);
      }
    }
    // For the relief shadows' correction (seed 002): the crests of the road's profile, the
    // rounded verge.
    m.curvature = vertex_curvatures(m);
    chunks.push_back(std::move(m));
  }
}

}  // namespace

std::vector<std::vector<MeshData>> build_road_chunks(const sim::RoadNetwork& roads) {
  // Every level's chunks start and end at the same cross-sections.
  std::vector<std::vector<MeshData>> levels(std::size(kRoadStepsM));
  for (int road = 0; road < roads.road_count(); ++road) {
    const std::vector<double> starts = roads.section_starts(road);
    const double length = roads.road_length(road);
    for (std::size_t i = 0; i < starts.size(); ++i) {
      const double s0 = starts[i], s1 = i + 1 < starts.size() ? starts[i + 1] : length;
      if (s1 - s0 < 1e-3) continue;
      for (std::size_t l = 0; l < levels.size(); ++l) {
        road_piece(roads, road, s0, s1, kRoadChunkM, kRoadStepsM[l], levels[l]);
      }
    }
  }
  std::vector<std::vector<MeshData>> chunks(levels.front().size());
  for (auto& level : levels) {
    for (std::size_t c = 0; c < chunks.size(); ++c) chunks[c].push_back(std::move(level[c]));
  }
  return chunks;
}

double terrain_height(const sim::RoadNetwork& roads, double x, double y) {
  const sim::RoadPlace p = roads.project({x, y}, 150.0);
  const sim::PavedSpan span = roads.paved(p.road, p.s);
  const double mid = 0.5 * (span.left + span.right);
  const double edge_t = p.t >= mid ? span.left : span.right;
  const double edge = roads.surface_height({p.road, p.s, edge_t}) - kVergeDrop - 0.15;
  const double d = std::abs(p.t - mid) - 0.5 * (span.left - span.right) - kVerge;
  // Far from the roads the ground rises to a ring of low mountains.
  glm::dvec2 lo, hi;
  roads.bounds(lo, hi);
  const glm::dvec2 centre = 0.5 * (lo + hi);
  const double ring = std::max(1000.0, 0.5 * glm::length(hi - lo) + 200.0);
  const double r = glm::length(glm::dvec2(x, y) - centre);
  const double far_hills =
      70.0 * glm::smoothstep(ring, ring + 800.0, r) * (0.7 + 0.3 * std::sin(x / 300.0 + y / 410.0));
  // (Around a simulator's roads, level fields a little below them, up to the far ring.)
  const double natural =
      edge + far_hills + (roads.own_scenery() ? hills(x, y) : -0.02 * std::min(d, 50.0));
  const double blend = glm::smoothstep(0.0, 60.0, d);
  return glm::mix(std::min(edge, natural), natural, blend);
}

SkirtedChunks build_terrain_chunks(const sim::RoadNetwork& roads) {
  // Bounds of the roads' reference lines plus a margin.
  glm::dvec2 lo(1e30), hi(-1e30);
  for (int road = 0; road < roads.road_count(); ++road) {
    const double length = roads.road_length(road);
    for (double s = 0.0; s < length; s += 20.0) {
      const glm::dvec2 p(roads.frame(road, s).position);
      lo = glm::min(lo, p);
      hi = glm::max(hi, p);
    }
  }
  lo -= kTerrainMargin;
  hi += kTerrainMargin;
  // 20 m cells, coarser over a network so wide that they would be more than 1024 across.
  const double cell = std::max(kTerrainCell, std::max(hi.x - lo.x, hi.y - lo.y) / 1024.0);
  const int nx = static_cast<int>(std::ceil((hi.x - lo.x) / cell));
  const int ny = static_cast<int>(std::ceil((hi.y - lo.y) / cell));
  std::vector<float> heights(static_cast<std::size_t>((nx + 1) * (ny + 1)));
  for (int j = 0; j <= ny; ++j) {
    for (int i = 0; i <= nx; ++i) {
      heights[j * (nx + 1) + i] =
          static_cast<float>(terrain_height(roads, lo.x + i * cell, lo.y + j * cell));
    }
  }
  auto h = [&](int i, int j) {
    i = std::clamp(i, 0, nx);
    j = std::clamp(j, 0, ny);
    return heights[j * (nx + 1) + i];
  };
  // A chunk's grid columns (or rows) at every step-th of the fine grid's, and always its last.
  auto samples = [](int first, int last, int step) {
    std::vector<int> out;
    for (int k = first; k < last; k += step) out.push_back(k);
    out.push_back(last);
    return out;
  };
  SkirtedChunks chunks;
  for (int cj = 0; cj < kTerrainChunks; ++cj) {
    for (int ci = 0; ci < kTerrainChunks; ++ci) {
      const int i0 = nx * ci / kTerrainChunks, i1 = nx * (ci + 1) / kTerrainChunks;
      const int j0 = ny * cj / kTerrainChunks, j1 = ny * (cj + 1) / kTerrainChunks;
      std::vector<MeshData> levels;
      std::vector<std::array<MeshData, 4>> skirts;
      for (int level = 0; level < kTerrainLevels; ++level) {
        const int step = 1 << level;
        const std::vector<int> is = samples(i0, i1, step), js = samples(j0, j1, step);
        auto vertex = [&](MeshData& m, int i, int j, float drop) {
          const float x = static_cast<float>(lo.x + i * cell);
          const float y = static_cast<float>(lo.y + j * cell);
          const glm::vec3 n =
              glm::normalize(glm::vec3(h(i - 1, j) - h(i + 1, j), h(i, j - 1) - h(i, j + 1),
                                       2.0f * static_cast<float>(cell)));
          return m.add_vertex({x, y, h(i, j) - drop}, n, {x, y});
        };
        MeshData m;
        for (int j : js) {
          for (int i : is) vertex(m, i, j, 0.0f);
        }
        const auto cols = static_cast<std::uint32_t>(is.size());
        for (std::uint32_t r = 0; r + 1 < js.size(); ++r) {
          for (std::uint32_t c = 0; c + 1 < cols; ++c) {
            const std::uint32_t a = r * cols + c;
            m.add_quad(a, a + 1, a + 1 + cols, a + cols);
          }
        }
        levels.push_back(std::move(m));
        // Skirts hanging from the edges hide the cracks where a neighbour is drawn finer.
        const float drop = static_cast<float>(kSkirtDepthPerCell * step * cell + 2.0);
        auto skirt = [&](const std::vector<std::pair<int, int>>& edge) {
          MeshData s;
          for (std::size_t k = 0; k + 1 < edge.size(); ++k) {
            const std::uint32_t a = vertex(s, edge[k].first, edge[k].second, 0.0f);
            const std::uint32_t b = vertex(s, edge[k + 1].first, edge[k + 1].second, 0.0f);
            const std::uint32_t c = vertex(s, edge[k + 1].first, edge[k + 1].second, drop);
            const std::uint32_t d = vertex(s, edge[k].first, edge[k].second, drop);
            s.add_quad(a, b, c, d);
          }
          return s;
        };
        std::vector<std::pair<int, int>> south, north, west, east;
        for (int i : is) {
          south.emplace_back(i, j0);
          north.emplace_back(i, j1);
        }
        for (int j : js) {
          west.emplace_back(i0, j);
          east.emplace_back(i1, j);
        }
        skirts.push_back({skirt(south), skirt(north), skirt(west), skirt(east)});
      }
      chunks.levels.push_back(std::move(levels));
      chunks.skirts.push_back(std::move(skirts));
      auto at = [](int i, int j) {
        return i < 0 || j < 0 || i >= kTerrainChunks || j >= kTerrainChunks
                   ? -1
                   : j * kTerrainChunks + i;
      };
      chunks.across.push_back({at(ci, cj - 1), at(ci, cj + 1), at(ci - 1, cj), at(ci + 1, cj)});
    }
  }
  return chunks;
}

namespace {

// A box of half sizes `half` along (along, across, up) about `centre`, in world coordinates.
void add_oriented_box(MeshData& m, const glm::vec3& centre, const glm::vec3& along,
                      const glm::vec3& half, float material) {
  MeshData local;
  local.add_box(-half, half, material);
  const glm::vec3 across(-along.y, along.x, 0.0f), up(0.0f, 0.0f, 1.0f);
  const auto base = static_cast<std::uint32_t>(m.vertices.size());
  for (const MeshVertex& v : local.vertices) {
    const glm::vec3 p = centre + along * v.position.x + across * v.position.y + up * v.position.z;
    const glm::vec3 n = along * v.normal.x + across * v.normal.y + up * v.normal.z;
    m.add_vertex(p, n, v.uv);
  }
  for (std::uint32_t i : local.indices) m.indices.push_back(base + i);
}

}  // namespace

std::vector<std::vector<MeshData>> build_street_light_chunks(
    const std::vector<sim::StreetLight>& lights) {
  constexpr std::size_t kPerChunk = 4;
  std::vector<std::vector<MeshData>> chunks;
  for (std::size_t first = 0; first < lights.size(); first += kPerChunk) {
    MeshData m;
    for (std::size_t i = first; i < std::min(lights.size(), first + kPerChunk); ++i) {
      const glm::vec3 lamp(lights[i].lamp_m), foot(lights[i].foot_m);
      glm::vec3 along(lamp.x - foot.x, lamp.y - foot.y, 0.0f);  // from the pole over the road
      const float reach = glm::length(along);
      along = reach > 1e-3f ? along / reach : glm::vec3(1.0f, 0.0f, 0.0f);
      const float top = lamp.z + 0.25f;
      // The pole, tapering in steps; the arm; the lamp's housing, its lens underneath.
      add_oriented_box(m, glm::vec3(foot.x, foot.y, 0.5f * (foot.z + top)), along,
                       glm::vec3(0.08f, 0.08f, 0.5f * (top - foot.z)), material::kBody);
      add_oriented_box(
          m, glm::vec3(foot) + along * (0.5f * reach) + glm::vec3(0.0f, 0.0f, top - foot.z - 0.04f),
          along, glm::vec3(0.5f * reach + 0.1f, 0.04f, 0.04f), material::kBody);
      add_oriented_box(m, lamp + glm::vec3(0.0f, 0.0f, 0.08f), along,
                       glm::vec3(0.35f, 0.16f, 0.07f), material::kBody);
      add_oriented_box(m, lamp, along, glm::vec3(0.3f, 0.13f, 0.012f), material::kStreetLamp);
    }
    chunks.push_back({std::move(m)});
  }
  return chunks;
}

}  // namespace downpour::render
