#include "server/render/scene_geometry.hpp"

#include <algorithm>
#include <cmath>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "server/render/mesh_curvature.hpp"

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

// The road in chunks of chunk_length_m with cross-sections every step_m.
std::vector<MeshData> road_chunks(const sim::Track& track, double chunk_length_m, double step) {
  const double half = track.paved_half_width();
  // Lateral stations of the cross-section, left positive: the verge's every metre, so that its
  // rounded fall (below) is a curve the mesh's curvature can be taken from.
  const double lanes = track.cross_section().lanes_each_way * track.cross_section().lane_width_m;
  std::vector<double> stations = {-lanes, 0.0, lanes};
  for (double t = 0.0; t <= kVerge + 1e-9; t += kVerge / 4.0) {
    stations.insert(stations.begin(), -half - t);
    stations.push_back(half + t);
  }
  std::vector<MeshData> chunks;
  const int rows_total = static_cast<int>(std::ceil(track.length() / step));
  const int rows_per_chunk = std::max(1, static_cast<int>(chunk_length_m / step));
  for (int first = 0; first < rows_total; first += rows_per_chunk) {
    MeshData m;
    const int last = std::min(rows_total, first + rows_per_chunk);
    for (int row = first; row <= last; ++row) {
      const double s = std::min(row * step, track.length());
      const sim::TrackFrame f = track.at(s);
      for (double lat : stations) {
        const double clamped = std::clamp(lat, -half, half);
        const double t = std::max(std::abs(lat) - half, 0.0) / kVerge;
        // The verge rounds over from the pavement's edge: level there, falling ever faster.
        const double z = track.surface_height(s, clamped) - kVergeDrop * t * t;
        const glm::dvec2 xy = glm::dvec2(f.position) + f.left * lat;
        // Normal from the cross-slope and the grade.
        const double cross = std::abs(lat) < 1e-9
                                 ? 0.0
                                 : (std::abs(lat) <= half ? track.cross_section().crown_slope
                                                          : 2.0 * kVergeDrop * t / kVerge) *
                                       (lat > 0 ? -1.0 : 1.0);
        const glm::dvec3 forward(std::cos(f.heading_rad), std::sin(f.heading_rad), f.grade);
        const glm::dvec3 side(f.left.x, f.left.y, cross);
        const glm::dvec3 n = glm::normalize(glm::cross(forward, side));
        m.add_vertex(glm::vec3(xy.x, xy.y, z), glm::vec3(n), glm::vec2(lat, s));
      }
    }
    const int cols = static_cast<int>(stations.size());
    for (int r = 0; r < last - first; ++r) {
      for (int c = 0; c + 1 < cols; ++c) {
        const auto i = static_cast<std::uint32_t>(r * cols + c);
        m.add_quad(i, i + 1, i + 1 + cols, i + cols);
      }
    }
    // For the relief shadows' correction (seed 002): the crests of the road's profile, the
    // rounded verge.
    m.curvature = vertex_curvatures(m);
    chunks.push_back(std::move(m));
  }
  return chunks;
}

}  // namespace

std::vector<std::vector<MeshData>> build_road_chunks(const sim::Track& track) {
  // Every level's chunks start and end at the same cross-sections (steps divide the length).
  std::vector<std::vector<MeshData>> levels;
  for (double step : kRoadStepsM) levels.push_back(road_chunks(track, kRoadChunkM, step));
  std::vector<std::vector<MeshData>> chunks(levels.front().size());
  for (auto& level : levels) {
    for (std::size_t c = 0; c < chunks.size(); ++c) chunks[c].push_back(std::move(level[c]));
  }
  return chunks;
}

double terrain_height(const sim::Track& track, double x, double y) {
  const sim::Track::Projection p = track.project({x, y}, 150.0);
  const double half = track.paved_half_width();
  const double edge = track.surface_height(p.s, std::copysign(half, p.lateral)) - kVergeDrop - 0.15;
  const double d = std::abs(p.lateral) - half - kVerge;
  // Far from the track the ground rises to a ring of low mountains.
  const glm::dvec2 centre(450.0, 250.0);
  const double r = glm::length(glm::dvec2(x, y) - centre);
  const double far_hills =
      70.0 * glm::smoothstep(1000.0, 1800.0, r) * (0.7 + 0.3 * std::sin(x / 300.0 + y / 410.0));
  const double natural = edge + hills(x, y) + far_hills;
  const double blend = glm::smoothstep(0.0, 60.0, d);
  return glm::mix(std::min(edge, natural), natural, blend);
}

std::vector<std::vector<MeshData>> build_terrain_chunks(const sim::Track& track) {
  // Bounds of the track plus a margin.
  glm::dvec2 lo(1e30), hi(-1e30);
  for (double s = 0.0; s < track.length(); s += 20.0) {
    const glm::dvec2 p(track.at(s).position);
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  lo -= kTerrainMargin;
  hi += kTerrainMargin;
  const int nx = static_cast<int>(std::ceil((hi.x - lo.x) / kTerrainCell));
  const int ny = static_cast<int>(std::ceil((hi.y - lo.y) / kTerrainCell));
  std::vector<float> heights(static_cast<std::size_t>((nx + 1) * (ny + 1)));
  for (int j = 0; j <= ny; ++j) {
    for (int i = 0; i <= nx; ++i) {
      heights[j * (nx + 1) + i] = static_cast<float>(
          terrain_height(track, lo.x + i * kTerrainCell, lo.y + j * kTerrainCell));
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
  std::vector<std::vector<MeshData>> chunks;
  for (int cj = 0; cj < kTerrainChunks; ++cj) {
    for (int ci = 0; ci < kTerrainChunks; ++ci) {
      const int i0 = nx * ci / kTerrainChunks, i1 = nx * (ci + 1) / kTerrainChunks;
      const int j0 = ny * cj / kTerrainChunks, j1 = ny * (cj + 1) / kTerrainChunks;
      std::vector<MeshData> levels;
      for (int level = 0; level < kTerrainLevels; ++level) {
        const int step = 1 << level;
        const std::vector<int> is = samples(i0, i1, step), js = samples(j0, j1, step);
        MeshData m;
        auto vertex = [&](int i, int j, float drop) {
          const float x = static_cast<float>(lo.x + i * kTerrainCell);
          const float y = static_cast<float>(lo.y + j * kTerrainCell);
          const glm::vec3 n =
              glm::normalize(glm::vec3(h(i - 1, j) - h(i + 1, j), h(i, j - 1) - h(i, j + 1),
                                       2.0f * static_cast<float>(kTerrainCell)));
          return m.add_vertex({x, y, h(i, j) - drop}, n, {x, y});
        };
        for (int j : js) {
          for (int i : is) vertex(i, j, 0.0f);
        }
        const auto cols = static_cast<std::uint32_t>(is.size());
        for (std::uint32_t r = 0; r + 1 < js.size(); ++r) {
          for (std::uint32_t c = 0; c + 1 < cols; ++c) {
            const std::uint32_t a = r * cols + c;
            m.add_quad(a, a + 1, a + 1 + cols, a + cols);
          }
        }
        // Skirts hanging from the edges hide the cracks where a neighbour is drawn finer.
        const float drop = static_cast<float>(kSkirtDepthPerCell * step * kTerrainCell + 2.0);
        auto skirt = [&](const std::vector<std::pair<int, int>>& edge) {
          for (std::size_t k = 0; k + 1 < edge.size(); ++k) {
            const std::uint32_t a = vertex(edge[k].first, edge[k].second, 0.0f);
            const std::uint32_t b = vertex(edge[k + 1].first, edge[k + 1].second, 0.0f);
            const std::uint32_t c = vertex(edge[k + 1].first, edge[k + 1].second, drop);
            const std::uint32_t d = vertex(edge[k].first, edge[k].second, drop);
            m.add_quad(a, b, c, d);
          }
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
        for (const auto* edge : {&south, &north, &west, &east}) skirt(*edge);
        levels.push_back(std::move(m));
      }
      chunks.push_back(std::move(levels));
    }
  }
  return chunks;
}

}  // namespace downpour::render
