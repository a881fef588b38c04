// The water on the road: the windows' cells, the flow between them and what the renderer draws.
// Moving the windows with the car, and handing the water between old and new windows and the
// records, is road_water_move.cpp.
#include "server/sim/road_water.hpp"

#include <algorithm>
#include <cmath>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

namespace downpour::sim {

namespace {

// How far the verge lies below the paved edge, for the slope that drains the edge cells.
constexpr double kVergeDropM = 0.05;

int floor_div(int a, int b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

}  // namespace

RoadState road_state(double water_m, const RoadWaterConfig& config) {
  if (water_m < config.wet_m) return RoadState::kDry;
  const double standing = water_m - config.capacity_m;
  return standing < config.drench_m   ? RoadState::kWet
         : standing < config.puddle_m ? RoadState::kDrench
                                      : RoadState::kPuddle;
}

double RoadWaterImage::reach_m(int level) const {
  auto middle = [&](int l) { return (glm::dvec2(origins[l]) + 0.5 * cells) * level_cell_m(l); };
  const glm::dvec2 off = glm::abs(middle(level) - middle(0));
  return 0.5 * cells * level_cell_m(level) + std::max(off.x, off.y);
}

glm::vec2 RoadWaterImage::at(glm::dvec2 xy) const {
  for (int l = 0; l < levels; ++l) {
    const glm::ivec2 cell = glm::ivec2(glm::floor(xy / level_cell_m(l))) - origins[l];
    if (cell.x < 0 || cell.y < 0 || cell.x >= cells || cell.y >= cells) continue;
    const std::size_t c = (static_cast<std::size_t>(l) * cells + cell.y) * cells + cell.x;
    return {water_standing_mm[2 * c], water_standing_mm[2 * c + 1]};
  }
  return {mean_water_mm, mean_standing_mm};
}

RoadWater::RoadWater(const RoadSurface& surface, RoadWaterConfig config)
    : surface_(surface),
      config_(config),
      n_(std::max(64, config.cells / 8 * 8)),
      levels_(std::clamp(config.levels, 1, kRoadWaterMaxLevels)) {
  const std::size_t count = static_cast<std::size_t>(levels_) * n_ * n_;
  ground_.assign(count, 0.0);
  water_.assign(count, 0.0);
  places_.assign(count, RoadPlace{});
  hollow_.assign(count, 0.0);
  paved_.assign(count, 0);
  owned_.assign(count, 0);
  outflow_.assign(count, 0.0);
}

std::array<glm::ivec2, kRoadWaterMaxLevels> RoadWater::ring_origins(glm::dvec2 centre,
                                                                    double cell_m, int cells,
                                                                    int levels) {
  // On a multiple of 8 cells: even, and a window moves only every 8 of its cells (2 m for the
  // finest), in strips, not on every step of a fast car (the car stays within 4 cells of the
  // middle).
  constexpr int kSnap = 8;
  std::array<glm::ivec2, kRoadWaterMaxLevels> out{};
  for (int l = 0; l < std::min(levels, kRoadWaterMaxLevels); ++l) {
    const double size = cell_m * static_cast<double>(1 << l);
    const glm::ivec2 o = glm::ivec2(glm::floor(centre / size)) - glm::ivec2(cells / 2 - kSnap / 2);
    out[l] = {kSnap * floor_div(o.x, kSnap), kSnap * floor_div(o.y, kSnap)};
  }
  return out;
}

void RoadWater::sample(int level, glm::ivec2 cell, std::size_t c, const RoadPlace& guess) {
  const double size = cell_m(level);
  const glm::dvec2 xy = (glm::dvec2(cell) + 0.5) * size;
  const RoadPlace p = surface_.project_near(xy, guess);
  places_[c] = p;
  paved_[c] = surface_.paved(p);
  if (level == 0) {
    ground_[c] = surface_.height_at(p);
    hollow_[c] = held_at(p);
    return;
  }
  // A coarse cell: the section's height at its centre, and the mean of what the hollows hold
  // across it, at points 1/8 m apart across the road (a rut's water lies in a narrow band; along
  // the road, ruts change slowly).
  const int points = 4 << (level - 1);
  double sum = 0.0;
  if (paved_[c] || surface_.paved({p.road, p.s, p.t - 0.5 * size}) ||
      surface_.paved({p.road, p.s, p.t + 0.5 * size})) {
    for (int k = 0; k < points; ++k) {
      const double u = ((k + 0.5) / points - 0.5) * size;
      sum += held_at({p.road, p.s, p.t + u});
    }
  }
  hollow_[c] = sum / points;
  ground_[c] = surface_.roads().surface_height(p);
}

double RoadWater::held_at(const RoadPlace& place) const {
  // Water at a point stays if the ground rises either way across the road: the highest ground
  // within a metre each way is that way's rim, and the lower rim is where it spills. (A rut across
  // the crown's slope holds what lies below its lower lip. Along the road it runs with the grade,
  // but a rut is fed along its whole length as it runs, so it stays full.)
  if (!surface_.paved(place)) return 0.0;
  auto height = [&](double u) { return surface_.height_at({place.road, place.s, u}); };
  const double lateral = place.t;
  const double here = height(lateral);
  double spill = 1e300;
  for (const double way : {1.0, -1.0}) {
    double rim = -1e300;
    for (const double d : {0.2, 0.35, 0.6, 1.0}) rim = std::max(rim, height(lateral + way * d));
    spill = std::min(spill, rim);
  }
  return std::max(spill - here, 0.0);
}

void RoadWater::sample_window(int level) {
  // Every cell from the surface, from the middle out, each from its neighbour's place along the
  // track, the middle one's from a search of the whole track.
  const int n = n_, m = n / 2;
  const glm::dvec2 middle = (glm::dvec2(origins_[level] + glm::ivec2(m)) + 0.5) * cell_m(level);
  auto at = [&](int i, int j, const RoadPlace& guess) {
    sample(level, origins_[level] + glm::ivec2(i, j), flat(level, i, j), guess);
  };
  at(m, m, surface_.roads().project(middle, 40.0));
  for (int i = m + 1; i < n; ++i) at(i, m, places_[flat(level, i - 1, m)]);
  for (int i = m - 1; i >= 0; --i) at(i, m, places_[flat(level, i + 1, m)]);
  for (int j = m + 1; j < n; ++j)
    for (int i = 0; i < n; ++i) at(i, j, places_[flat(level, i, j - 1)]);
  for (int j = m - 1; j >= 0; --j)
    for (int i = 0; i < n; ++i) at(i, j, places_[flat(level, i, j + 1)]);
}

void RoadWater::settle(Record& r) {
  // The rain that fell on it while it was away fills its texture, the rest runs off as a film: over
  // T, under an even inflow R, a film f runs down to f e^(-T/tau) + R tau (1 - e^(-T/tau)).
  const double rain = (rain_m_ - r.rain_m) * r.paved_m2;
  const double into = std::clamp(config_.capacity_m * r.paved_m2 - r.texture_m3, 0.0, rain);
  r.texture_m3 += into;
  ledger_.rain_in_m3 += rain;
  const double span = time_s_ - r.time_s, tau = config_.film_runoff_s;
  const double keep = std::exp(-span / tau);
  const double inflow = rain - into;
  const double left =
      r.film_m3 * keep + (span > 1e-9 ? inflow * tau / span * (1.0 - keep) : inflow);
  ledger_.drained_m3 += r.film_m3 + inflow - left;
  r.film_m3 = left;
  r.rain_m = rain_m_;
  const double held = r.texture_m3 + r.pooled_m3;
  const double gone =
      std::min(held, config_.evaporation_m_per_s * (dry_time_s_ - r.dry_time_s) * r.paved_m2);
  if (held > 0.0) {
    r.texture_m3 -= gone * (r.texture_m3 / held);
    r.pooled_m3 = std::max(held - gone - r.texture_m3, 0.0);
  }
  ledger_.evaporated_m3 += gone;
  r.dry_time_s = dry_time_s_;
  r.time_s = time_s_;
}

void RoadWater::trim_records(glm::dvec2 centre) {
  if (records_.size() <= config_.max_records) return;
  // The farther half goes (its water counted as drained: the road far behind is not drawn again
  // for a long while).
  const double size = cell_m(levels_ - 1);
  std::vector<std::pair<double, Key>> by_distance;
  by_distance.reserve(records_.size());
  for (const auto& [key, r] : records_) {
    const glm::dvec2 d = (glm::dvec2(key.first, key.second) + 0.5) * size - centre;
    by_distance.emplace_back(glm::dot(d, d), key);
  }
  std::nth_element(by_distance.begin(), by_distance.begin() + by_distance.size() / 2,
                   by_distance.end());
  for (std::size_t k = by_distance.size() / 2; k < by_distance.size(); ++k) {
    const auto found = records_.find(by_distance[k].second);
    settle(found->second);
    const Record& r = found->second;
    ledger_.drained_m3 += r.texture_m3 + r.film_m3 + r.pooled_m3;
    records_.erase(found);
  }
}

void RoadWater::step(glm::dvec2 centre, double rain_mm_h, double dt_s) {
  const std::array<glm::ivec2, kRoadWaterMaxLevels> origins =
      ring_origins(centre, config_.cell_m, n_, levels_);
  if (!placed_ || origins != origins_) {
    move_to(origins);
    trim_records(centre);
  }
  if (!(dt_s > 0.0)) return;
  const int n = n_;
  const std::size_t per_level = layer();
  const std::size_t count = water_.size();
  const bool raining = rain_mm_h > 0.0;
  time_s_ += dt_s;
  if (!raining) dry_time_s_ += dt_s;
  if (raining) rain_m_ += rain_mm_h / 3.6e6 * dt_s;

  // Rain in, or evaporation out (the air is saturated while it rains), on the cells that hold
  // their place's water.
  for (int l = 0; l < levels_; ++l) {
    const double a = area(l);
    if (raining) {
      const double depth = rain_mm_h / 3.6e6 * dt_s;
      std::size_t cells = 0;
      for (std::size_t c = l * per_level; c < (l + 1) * per_level; ++c) {
        if (!paved_[c] || !owned_[c]) continue;
        water_[c] += depth;
        ++cells;
      }
      ledger_.rain_in_m3 += depth * a * static_cast<double>(cells);
    } else {
      const double depth = config_.evaporation_m_per_s * dt_s;
      double gone = 0.0;
      for (std::size_t c = l * per_level; c < (l + 1) * per_level; ++c) {
        const double e = std::min(water_[c], depth);
        water_[c] -= e;
        gone += e;
      }
      ledger_.evaporated_m3 += gone * a;
    }
  }

  // Standing water runs to the four neighbours by water level: Manning's sheet flow across each
  // edge, v = h^(2/3) sqrt(slope) / n, from the higher level to the lower, limited to what levels
  // the two cells (a cell never gives more than it has standing: outflows scale down together).
  // A paved cell beside an unpaved one drains into it (the verge lies lower): off the road. Within
  // a level between the cells that hold water, and across each ring's border between a fine cell
  // and the coarse one beside it (as wide as the fine cell, its centre 1.5 fine cells away).
  const double capacity = config_.capacity_m;
  const double inv_n = 1.0 / config_.manning_n;
  auto standing = [&](std::size_t c) { return std::max(water_[c] - capacity - storage(c), 0.0); };
  flow_x_.assign(count, 0.0);
  flow_y_.assign(count, 0.0);
  std::fill(outflow_.begin(), outflow_.end(), 0.0);
  crossings_.clear();
  // Flow from a to b (m^3, signed) across an edge `width` wide between centres `distance` apart;
  // `area_a`, `area_b`: the cells'.
  auto edge = [&](std::size_t a, std::size_t b, double width, double distance, double area_a,
                  double area_b) -> double {
    if (!paved_[a] && !paved_[b]) return 0.0;
    const double ha = standing(a), hb = standing(b);
    double level_a = ground_[a] + ha, level_b = ground_[b] + hb;
    if (!paved_[a]) level_a = ground_[b] - kVergeDropM;  // a sink beside b
    if (!paved_[b]) level_b = ground_[a] - kVergeDropM;
    const double dl = level_a - level_b;
    const std::size_t up = dl > 0.0 ? a : b;
    const double h = dl > 0.0 ? ha : hb;
    if (h <= 0.0 || dl == 0.0) return 0.0;
    const double v = inv_n * std::cbrt(h * h) * std::sqrt(std::abs(dl) / distance);
    // At most what levels them (half the difference each way, over the smaller cell), or all that
    // stands over a sink.
    const bool to_sink = !paved_[dl > 0.0 ? b : a];
    const double limit = to_sink ? h * (dl > 0.0 ? area_a : area_b)
                                 : 0.5 * std::min(std::abs(dl), h) * std::min(area_a, area_b);
    const double volume = std::min(v * h * width * dt_s, limit);
    outflow_[up] += volume;
    return dl > 0.0 ? volume : -volume;
  };
  for (int l = 0; l < levels_; ++l) {
    const double size = cell_m(l), a = area(l);
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        const std::size_t c = flat(l, i, j);
        if (!owned_[c]) continue;
        if (i + 1 < n && owned_[c + 1]) flow_x_[c] = edge(c, c + 1, size, size, a, a);
        if (j + 1 < n && owned_[c + n]) flow_y_[c] = edge(c, c + n, size, size, a, a);
        // Across the border into the next ring.
        if (l + 1 >= levels_ || (i > 0 && j > 0 && i + 1 < n && j + 1 < n)) continue;
        const glm::ivec2 q = origins_[l] + glm::ivec2(i, j);
        for (const glm::ivec2 step : {glm::ivec2(-1, 0), {1, 0}, {0, -1}, {0, 1}}) {
          const glm::ivec2 d = q + step - origins_[l];
          if (d.x >= 0 && d.y >= 0 && d.x < n && d.y < n) continue;
          const glm::ivec2 e = coarser(q + step, 1) - origins_[l + 1];
          const std::size_t b = flat(l + 1, e.x, e.y);
          crossings_.push_back({c, b, edge(c, b, size, 1.5 * size, a, 4.0 * a)});
        }
      }
    }
  }
  // Each cell's outflows scaled so that together they take no more than it has standing.
  for (int l = 0; l < levels_; ++l) {
    const double a = area(l);
    for (std::size_t c = l * per_level; c < (l + 1) * per_level; ++c) {
      const double have = standing(c) * a;
      outflow_[c] = outflow_[c] > have ? have / outflow_[c] : 1.0;  // now the scale
    }
  }
  double drained = 0.0;
  auto apply = [&](std::size_t a, std::size_t b, double volume, double area_a, double area_b) {
    if (volume == 0.0) return;
    const std::size_t up = volume > 0.0 ? a : b, down = volume > 0.0 ? b : a;
    const double moved = std::abs(volume) * outflow_[up];
    water_[up] -= moved / (volume > 0.0 ? area_a : area_b);
    if (paved_[down]) {
      water_[down] += moved / (volume > 0.0 ? area_b : area_a);
    } else {
      drained += moved;
    }
  };
  for (int l = 0; l < levels_; ++l) {
    const double a = area(l);
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        const std::size_t c = flat(l, i, j);
        if (i + 1 < n) apply(c, c + 1, flow_x_[c], a, a);
        if (j + 1 < n) apply(c, c + n, flow_y_[c], a, a);
      }
    }
  }
  for (const Crossing& x : crossings_) {
    const double a = area(static_cast<int>(x.fine / per_level));
    apply(x.fine, x.coarse, x.volume, a, 4.0 * a);
  }
  ledger_.drained_m3 += drained;
}

int RoadWater::find(glm::dvec2 xy) const {
  if (!placed_) return -1;
  for (int l = 0; l < levels_; ++l) {
    const glm::ivec2 d = glm::ivec2(glm::floor(xy / cell_m(l))) - origins_[l];
    if (d.x < 0 || d.y < 0 || d.x >= n_ || d.y >= n_) continue;
    return static_cast<int>(flat(l, d.x, d.y));
  }
  return -1;
}

double RoadWater::water_m(glm::dvec2 xy) const {
  const int c = find(xy);
  return c < 0 ? 0.0 : water_[c];
}

double RoadWater::standing_m(glm::dvec2 xy) const {
  return std::max(water_m(xy) - config_.capacity_m, 0.0);
}

double RoadWater::take(glm::dvec2 xy, double volume_m3) {
  const int c = find(xy);
  if (c < 0 || !(volume_m3 > 0.0)) return 0.0;
  const double a = area(c / (n_ * n_));
  const double taken = std::min(volume_m3, water_[c] * a);
  water_[c] -= taken / a;
  ledger_.thrown_m3 += taken;
  return taken;
}

double RoadWater::give(glm::dvec2 xy, double volume_m3) {
  const int c = find(xy);
  if (c < 0 || !paved_[c] || !(volume_m3 > 0.0)) return 0.0;
  water_[c] += volume_m3 / area(c / (n_ * n_));
  ledger_.returned_m3 += volume_m3;
  return volume_m3;
}

void RoadWater::image(RoadWaterImage& out) const {
  const int n = n_;
  out.levels = levels_;
  out.origins = origins_;
  out.cell_m = config_.cell_m;
  out.cells = n;
  out.capacity_mm = config_.capacity_m * 1e3;
  out.water_standing_mm.assign(water_.size() * 2, 0.0f);
  out.max_standing_mm = 0.0f;
  out.mean_water_mm = out.mean_standing_mm = 0.0f;
  if (!placed_) return;  // before the first step: all dry
  double water_sum = 0.0, standing_sum = 0.0, paved_area = 0.0;
  auto put = [&](std::size_t c) {
    out.water_standing_mm[2 * c] = static_cast<float>(sheet_m(c) * 1e3);
    out.water_standing_mm[2 * c + 1] =
        static_cast<float>(std::max(water_[c] - config_.capacity_m, 0.0) * 1e3);
  };
  for (int l = 0; l < levels_; ++l) {
    const double a = area(l);
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        const std::size_t c = flat(l, i, j);
        if (owned_[c]) {
          put(c);
          out.max_standing_mm = std::max(out.max_standing_mm, out.water_standing_mm[2 * c + 1]);
          if (paved_[c]) {
            water_sum += sheet_m(c) * a;
            standing_sum += std::max(water_[c] - config_.capacity_m, 0.0) * a;
            paved_area += a;
          }
          continue;
        }
        // A cell a finer ring holds: the mean of its four finer cells (as drawn).
        const glm::ivec2 d = 2 * (origins_[l] + glm::ivec2(i, j)) - origins_[l - 1];
        for (int k = 0; k < 4; ++k) {
          const std::size_t f = flat(l - 1, d.x + (k & 1), d.y + (k >> 1));
          out.water_standing_mm[2 * c] += 0.25f * out.water_standing_mm[2 * f];
          out.water_standing_mm[2 * c + 1] += 0.25f * out.water_standing_mm[2 * f + 1];
        }
      }
    }
    // An unpaved cell beside the road shows the water of its paved neighbours, so that the road's
    // edge, drawn smooth, never shows the cells' steps (the verge draws its own wetness).
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        const std::size_t c = flat(l, i, j);
        if (paved_[c] || !owned_[c]) continue;
        for (const auto& [di, dj] : {std::pair{-1, 0}, {1, 0}, {0, -1}, {0, 1}}) {
          if (i + di < 0 || i + di >= n || j + dj < 0 || j + dj >= n) continue;
          const std::size_t d = flat(l, i + di, j + dj);
          if (!paved_[d] || !owned_[d]) continue;
          out.water_standing_mm[2 * c] =
              std::max(out.water_standing_mm[2 * c], static_cast<float>(sheet_m(d) * 1e3));
          out.water_standing_mm[2 * c + 1] =
              std::max(out.water_standing_mm[2 * c + 1],
                       static_cast<float>(std::max(water_[d] - config_.capacity_m, 0.0) * 1e3));
        }
      }
    }
  }
  out.mean_water_mm = paved_area > 0.0 ? static_cast<float>(water_sum / paved_area * 1e3) : 0.0f;
  out.mean_standing_mm =
      paved_area > 0.0 ? static_cast<float>(standing_sum / paved_area * 1e3) : 0.0f;
}

double RoadWater::stored_m3() const {
  double sum = 0.0;
  const std::size_t per_level = layer();
  for (int l = 0; l < levels_; ++l) {
    double level = 0.0;
    for (std::size_t c = l * per_level; c < (l + 1) * per_level; ++c) level += water_[c];
    sum += level * area(l);
  }
  for (const auto& [key, r] : records_) sum += r.texture_m3 + r.film_m3 + r.pooled_m3;
  return sum;
}

}  // namespace downpour::sim
