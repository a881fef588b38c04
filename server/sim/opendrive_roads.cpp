#include "server/sim/opendrive_roads.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <glm/common.hpp>
#include <glm/exponential.hpp>
#include <glm/geometric.hpp>

namespace downpour::sim {

namespace {

constexpr double kSampleStepM = 2.0;
constexpr double kMinCellM = 16.0;
constexpr int kMaxCellsAcross = 1024;
// A session's roads may span this much, and a road's paved width reach this far from its reference
// line: beyond, a file describes no road a car drives on, and would only cost.
constexpr double kMaxExtentM = 100'000.0;
constexpr double kMaxReachM = 200.0;
// project_near() searches every road near a place its guess's road does not hold, within this.
constexpr double kNearSearchM = 30.0;

// Lane types a car drives in (its wheel paths worn into it, its lines dashed between them).
bool driven(const std::string& type) {
  return type == "driving" || type == "entry" || type == "exit" || type == "onRamp" ||
         type == "offRamp" || type == "connectingRamp" || type == "bidirectional" ||
         type == "slipLane";
}

LaneMark mark_of(const road::Lane& lane, double ds) {
  LaneMark out;
  const road::RoadMark* m = nullptr;
  for (const road::RoadMark& candidate : lane.marks) {
    if (candidate.s_offset <= ds + 1e-9) m = &candidate;
  }
  if (!m) return out;
  using Kind = LaneMark::Kind;
  const std::string& t = m->type;
  out.kind = t == "solid"           ? Kind::kSolid
             : t == "broken"        ? Kind::kBroken
             : t == "botts dots"    ? Kind::kBroken
             : t == "solid solid"   ? Kind::kSolidSolid
             : t == "solid broken"  ? Kind::kSolidBroken
             : t == "broken solid"  ? Kind::kBrokenSolid
             : t == "broken broken" ? Kind::kBrokenBroken
                                    : Kind::kNone;
  out.width_m = m->width > 0.0 ? std::clamp(m->width, 0.05, 0.5) : 0.12;
  out.spacing_m = 2.0 * out.width_m;
  out.yellow = m->colour == "yellow" || m->colour == "orange";
  return out;
}

}  // namespace

OpenDriveRoads::OpenDriveRoads(road::Network network) : network_(std::move(network)) {
  if (network_.roads.empty()) throw std::invalid_argument("a road network without roads");
  lo_ = glm::dvec2(std::numeric_limits<double>::max());
  hi_ = -lo_;
  for (int r = 0; r < road_count(); ++r) {
    const road::Road& road = network_.roads[r];
    const int n = std::max(1, static_cast<int>(std::ceil(road.length / kSampleStepM)));
    for (int i = 0; i <= n; ++i) {
      const double s = road.length * i / n;
      const road::RefPoint p = road.reference(s);
      samples_.push_back({{p.x, p.y}, s, r});
      const PavedSpan span = paved(r, s);
      const double reach = std::max(std::abs(span.left), std::abs(span.right));
      widest_m_ = std::max(widest_m_, reach);
      lo_ = glm::min(lo_, glm::dvec2(p.x, p.y) - reach);
      hi_ = glm::max(hi_, glm::dvec2(p.x, p.y) + reach);
    }
  }
  if (widest_m_ > kMaxReachM) {
    throw std::invalid_argument("a road's lanes reach " + std::to_string(widest_m_) +
                                " m from its reference line (at most " +
                                std::to_string(kMaxReachM) + ")");
  }
  const glm::dvec2 extent = hi_ - lo_;
  if (std::max(extent.x, extent.y) > kMaxExtentM) {
    throw std::invalid_argument("the roads span " + std::to_string(std::max(extent.x, extent.y)) +
                                " m (at most " + std::to_string(kMaxExtentM) + ")");
  }
  cell_m_ = std::max(kMinCellM, std::max(extent.x, extent.y) / kMaxCellsAcross);
  cells_ = glm::max(glm::ivec2(glm::ceil(extent / cell_m_)), glm::ivec2(1));
  // A counting sort of the samples by cell.
  const std::size_t count = static_cast<std::size_t>(cells_.x) * cells_.y;
  cell_start_.assign(count + 1, 0);
  std::vector<std::uint32_t> cell(samples_.size());
  for (std::size_t i = 0; i < samples_.size(); ++i) {
    const glm::ivec2 c = cell_of(samples_[i].xy);
    cell[i] = static_cast<std::uint32_t>(c.y * cells_.x + c.x);
    ++cell_start_[cell[i] + 1];
  }
  for (std::size_t c = 0; c < count; ++c) cell_start_[c + 1] += cell_start_[c];
  cell_samples_.resize(samples_.size());
  std::vector<std::uint32_t> next(cell_start_.begin(), cell_start_.end() - 1);
  for (std::size_t i = 0; i < samples_.size(); ++i) {
    cell_samples_[next[cell[i]]++] = static_cast<std::uint32_t>(i);
  }
  // Each cell's nearest sample, near enough: its own samples' nearest to its centre, carried to
  // the cells without by two sweeps across the grid (each cell takes a neighbour's if nearer).
  constexpr std::uint32_t kNone = UINT32_MAX;
  near_.assign(count, kNone);
  auto centre = [&](int x, int y) { return lo_ + (glm::dvec2(x, y) + 0.5) * cell_m_; };
  auto d2 = [&](std::uint32_t k, int x, int y) {
    const glm::dvec2 d = samples_[k].xy - centre(x, y);
    return glm::dot(d, d);
  };
  for (int y = 0; y < cells_.y; ++y) {
    for (int x = 0; x < cells_.x; ++x) {
      const std::size_t c = static_cast<std::size_t>(y) * cells_.x + x;
      for (std::uint32_t k = cell_start_[c]; k < cell_start_[c + 1]; ++k) {
        const std::uint32_t i = cell_samples_[k];
        if (near_[c] == kNone || d2(i, x, y) < d2(near_[c], x, y)) near_[c] = i;
      }
    }
  }
  auto take = [&](int x, int y, int nx, int ny) {
    if (nx < 0 || ny < 0 || nx >= cells_.x || ny >= cells_.y) return;
    const std::uint32_t other = near_[static_cast<std::size_t>(ny) * cells_.x + nx];
    std::uint32_t& mine = near_[static_cast<std::size_t>(y) * cells_.x + x];
    if (other != kNone && (mine == kNone || d2(other, x, y) < d2(mine, x, y))) mine = other;
  };
  for (int y = 0; y < cells_.y; ++y) {
    for (int x = 0; x < cells_.x; ++x) {
      take(x, y, x - 1, y), take(x, y, x, y - 1), take(x, y, x - 1, y - 1),
          take(x, y, x + 1, y - 1);
    }
  }
  for (int y = cells_.y - 1; y >= 0; --y) {
    for (int x = cells_.x - 1; x >= 0; --x) {
      take(x, y, x + 1, y), take(x, y, x, y + 1), take(x, y, x + 1, y + 1),
          take(x, y, x - 1, y + 1);
    }
  }
}

glm::ivec2 OpenDriveRoads::cell_of(glm::dvec2 xy) const {
  const glm::dvec2 c = glm::floor((xy - lo_) / cell_m_);
  return glm::clamp(glm::ivec2(glm::clamp(c, glm::dvec2(-1.0), glm::dvec2(cells_))), glm::ivec2(0),
                    cells_ - 1);
}

std::vector<double> OpenDriveRoads::section_starts(int road) const {
  std::vector<double> out;
  for (const road::LaneSection& section : network_.roads[road].sections) {
    out.push_back(std::clamp(section.s, 0.0, network_.roads[road].length));
  }
  if (out.empty() || out.front() > 0.0) out.insert(out.begin(), 0.0);
  return out;
}

TrackFrame OpenDriveRoads::frame(int road, double s) const {
  const road::Road& r = network_.roads[road];
  s = std::clamp(s, 0.0, r.length);
  const road::RefPoint p = r.reference(s);
  TrackFrame f;
  f.position = glm::dvec3(p.x, p.y, r.height(s));
  f.heading_rad = p.heading;
  f.grade = road::eval_cubics_slope(r.elevation, s);
  f.left = glm::dvec2(-std::sin(p.heading), std::cos(p.heading));
  return f;
}

PavedSpan OpenDriveRoads::paved(int road, double s) const {
  const road::Road& r = network_.roads[road];
  const road::LaneSection& section = r.section_at(s);
  return {r.lane_border(s, -static_cast<int>(section.right.size())),
          r.lane_border(s, static_cast<int>(section.left.size()))};
}

double OpenDriveRoads::surface_height(const RoadPlace& place) const {
  const road::Road& r = network_.roads[place.road];
  const double s = std::clamp(place.s, 0.0, r.length);
  const PavedSpan span = paved(place.road, s);
  return r.surface_height(s, std::clamp(place.t, span.right, span.left));
}

LaneLayout OpenDriveRoads::lanes(int road, double s) const {
  const road::Road& r = network_.roads[road];
  s = std::clamp(s, 0.0, r.length);
  const road::LaneSection& section = r.section_at(s);
  const double ds = s - section.s;
  LaneLayout out;
  for (auto i = static_cast<int>(section.right.size()); i >= 1; --i) {
    const road::Lane& lane = section.right[i - 1];
    out.borders.push_back(r.lane_border(s, -i));
    out.marks.push_back(mark_of(lane, ds));
    out.driving.push_back(driven(lane.type));
  }
  out.centre = static_cast<int>(out.borders.size());
  out.borders.push_back(r.lane_offset(s));
  out.marks.push_back(mark_of(section.centre, ds));
  for (std::size_t i = 1; i <= section.left.size(); ++i) {
    const road::Lane& lane = section.left[i - 1];
    out.driving.push_back(driven(lane.type));
    out.borders.push_back(r.lane_border(s, static_cast<int>(i)));
    out.marks.push_back(mark_of(lane, ds));
  }
  return out;
}

RoadPlace OpenDriveRoads::foot(int road, glm::dvec2 xy, double s) const {
  const road::Road& r = network_.roads[road];
  s = std::clamp(s, 0.0, r.length);
  road::RefPoint p = r.reference(s);
  for (int i = 0; i < 8; ++i) {
    const double along = (xy.x - p.x) * std::cos(p.heading) + (xy.y - p.y) * std::sin(p.heading);
    const double next = std::clamp(s + along, 0.0, r.length);
    if (std::abs(next - s) < 1e-7) break;
    s = next;
    p = r.reference(s);
  }
  return {road, s, -(xy.x - p.x) * std::sin(p.heading) + (xy.y - p.y) * std::cos(p.heading)};
}

double OpenDriveRoads::off_road(glm::dvec2 xy, const RoadPlace& place) const {
  const road::Road& r = network_.roads[place.road];
  const PavedSpan span = paved(place.road, place.s);
  const double across = place.t < span.right  ? span.right - place.t
                        : place.t > span.left ? place.t - span.left
                                              : 0.0;
  double beyond = 0.0;
  if (place.s <= 0.0 || place.s >= r.length) {
    const road::RefPoint p = r.reference(place.s);
    const double along = (xy.x - p.x) * std::cos(p.heading) + (xy.y - p.y) * std::sin(p.heading);
    beyond = place.s <= 0.0 ? std::max(-along, 0.0) : std::max(along, 0.0);
  }
  return std::max(across, beyond);
}

RoadPlace OpenDriveRoads::project(glm::dvec2 xy, double fine_within_m) const {
  // The nearest sample of each road within reach: rings of cells outwards, until a ring is further
  // than the nearest sample plus the widest road (a point on a wide road may lie further from its
  // own reference line than from another's).
  struct Nearest {
    double d2 = std::numeric_limits<double>::max();
    double s = 0.0;
  };
  const glm::ivec2 centre = cell_of(xy);
  // A sample near the place, from its cell's: the search need go no further than it (and its
  // road's reach), and where even that is beyond fine_within_m, it is the answer.
  const Sample& hint = samples_[near_[static_cast<std::size_t>(centre.y) * cells_.x + centre.x]];
  double best_d2 = glm::dot(hint.xy - xy, hint.xy - xy);
  if (std::sqrt(best_d2) > fine_within_m + widest_m_ + 2.0 * kSampleStepM) {
    const TrackFrame f = frame(hint.road, hint.s);
    return {hint.road, hint.s, glm::dot(xy - glm::dvec2(f.position), f.left)};
  }
  thread_local std::vector<std::pair<int, Nearest>> roads;
  roads.clear();
  roads.push_back({hint.road, {best_d2, hint.s}});
  const int rings = std::max(cells_.x, cells_.y);
  for (int ring = 0; ring <= rings; ++ring) {
    const double ring_from = (ring - 1) * cell_m_;
    if (ring_from > std::sqrt(best_d2) + widest_m_ + 2.0 * kSampleStepM) break;
    for (int y = centre.y - ring; y <= centre.y + ring; ++y) {
      if (y < 0 || y >= cells_.y) continue;
      const bool edge_row = y == centre.y - ring || y == centre.y + ring;
      for (int x = centre.x - ring; x <= centre.x + ring; x += edge_row ? 1 : 2 * ring) {
        if (x >= 0 && x < cells_.x) {
          const std::size_t c = static_cast<std::size_t>(y) * cells_.x + x;
          for (std::uint32_t k = cell_start_[c]; k < cell_start_[c + 1]; ++k) {
            const Sample& sample = samples_[cell_samples_[k]];
            const glm::dvec2 d = sample.xy - xy;
            const double d2 = glm::dot(d, d);
            best_d2 = std::min(best_d2, d2);
            auto it = std::find_if(roads.begin(), roads.end(),
                                   [&](const auto& e) { return e.first == sample.road; });
            if (it == roads.end()) {
              roads.push_back({sample.road, {d2, sample.s}});
            } else if (d2 < it->second.d2) {
              it->second = {d2, sample.s};
            }
          }
        }
        if (ring == 0) break;
      }
    }
  }
  if (best_d2 > fine_within_m * fine_within_m) {
    // Scenery far from every road: the nearest sample's road, across from it.
    const auto it = std::min_element(roads.begin(), roads.end(), [](const auto& a, const auto& b) {
      return a.second.d2 < b.second.d2;
    });
    const TrackFrame f = frame(it->first, it->second.s);
    return {it->first, it->second.s, glm::dot(xy - glm::dvec2(f.position), f.left)};
  }
  RoadPlace best;
  double best_off = std::numeric_limits<double>::max();
  double best_inside = -1.0;
  for (const auto& [road, nearest] : roads) {
    if (nearest.d2 > glm::pow(std::sqrt(best_d2) + widest_m_ + 2.0 * kSampleStepM, 2.0)) continue;
    const RoadPlace place = foot(road, xy, nearest.s);
    const double off = off_road(xy, place);
    double inside = -1.0;
    if (off == 0.0) {
      const PavedSpan span = paved(road, place.s);
      inside = std::min(place.t - span.right, span.left - place.t);
    }
    if (off < best_off || (off == 0.0 && inside > best_inside)) {
      best = place, best_off = off, best_inside = inside;
    }
  }
  return best;
}

RoadPlace OpenDriveRoads::project_near(glm::dvec2 xy, const RoadPlace& guess) const {
  if (guess.road >= 0 && guess.road < road_count()) {
    const RoadPlace place = foot(guess.road, xy, guess.s);
    if (off_road(xy, place) == 0.0) return place;
  }
  // Off its road: the road that holds it, if one is near; else as good as scenery needs.
  return project(xy, kNearSearchM);
}

}  // namespace downpour::sim
