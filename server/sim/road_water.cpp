#include "server/sim/road_water.hpp"

#include <algorithm>
#include <cmath>

#include <glm/common.hpp>

namespace downpour::sim {

namespace {

// How far the verge lies below the paved edge, for the slope that drains the edge cells.
constexpr double kVergeDropM = 0.05;

int floor_div(int a, int b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

}  // namespace

RoadWater::RoadWater(const RoadSurface& surface, RoadWaterConfig config)
    : surface_(surface), config_(config), n_(std::max(config.cells, 4)) {
  record_cells_ = std::max(1, static_cast<int>(std::lround(config_.record_m / config_.cell_m)));
  const std::size_t count = static_cast<std::size_t>(n_) * n_;
  ground_.assign(count, 0.0);
  water_.assign(count, 0.0);
  paved_.assign(count, 0);
  outflow_.assign(count, 0.0);
}

RoadState road_state(double water_m, const RoadWaterConfig& config) {
  if (water_m < config.wet_m) return RoadState::kDry;
  const double standing = water_m - config.capacity_m;
  return standing < config.drench_m   ? RoadState::kWet
         : standing < config.puddle_m ? RoadState::kDrench
                                      : RoadState::kPuddle;
}

RoadWater::Key RoadWater::record_key(glm::ivec2 world) const {
  return {floor_div(world.x, record_cells_), floor_div(world.y, record_cells_)};
}

void RoadWater::settle(Record& r) {
  const double left = r.film_m3 * std::exp(-(time_s_ - r.time_s) / config_.film_runoff_s);
  ledger_.drained_m3 += r.film_m3 - left;
  r.film_m3 = left;
  const double area = config_.cell_m * config_.cell_m * r.cells_out;
  const double gone =
      std::min(r.volume_m3, config_.evaporation_m_per_s * (dry_time_s_ - r.dry_time_s) * area);
  r.volume_m3 -= gone;
  ledger_.evaporated_m3 += gone;
  r.dry_time_s = dry_time_s_;
  r.time_s = time_s_;
}

void RoadWater::leave_cell(int i, int j) {
  const std::size_t c = static_cast<std::size_t>(j) * n_ + i;
  const double area = config_.cell_m * config_.cell_m;
  const double w = water_[c];
  water_[c] = 0.0;
  const glm::ivec2 world = origin_ + glm::ivec2(i, j);
  if (state_of(w) == RoadState::kPuddle) {
    puddle_cells_.emplace(Key{world.x, world.y}, Record{w * area, 0.0, 1, dry_time_s_, time_s_});
    return;
  }
  const Key key = record_key(world);
  auto found = records_.find(key);
  if (found == records_.end()) {
    if (w <= 0.0) return;  // a dry cell leaves nothing to keep
    found = records_.emplace(key, Record{0.0, 0.0, 0, dry_time_s_, time_s_}).first;
  }
  Record& r = found->second;
  settle(r);
  r.volume_m3 += std::min(w, config_.capacity_m) * area;
  r.film_m3 += std::max(w - config_.capacity_m, 0.0) * area;
  r.cells_out += 1;
}

void RoadWater::fill_cell(int i, int j, glm::ivec2 world, double s_guess, double fresh_m) {
  const std::size_t c = static_cast<std::size_t>(j) * n_ + i;
  const glm::dvec2 xy = (glm::dvec2(world) + 0.5) * config_.cell_m;
  const Track::Projection p = surface_.project_near(xy, s_guess);
  ground_[c] = surface_.height_at(p.s, p.lateral);
  paved_[c] = surface_.paved(p.lateral);
  water_[c] = 0.0;
  const auto puddle = puddle_cells_.find(Key{world.x, world.y});
  if (puddle != puddle_cells_.end()) {
    settle(puddle->second);
    water_[c] = puddle->second.volume_m3 / (config_.cell_m * config_.cell_m);
    puddle_cells_.erase(puddle);
    return;
  }
  const auto found = records_.find(record_key(world));
  if (found == records_.end()) {
    // Rain fell here before the window came: as much as its cells hold (it enters the ledger as
    // rain now).
    if (paved_[c] && fresh_m > 0.0) {
      water_[c] = fresh_m;
      ledger_.rain_in_m3 += fresh_m * config_.cell_m * config_.cell_m;
    }
    return;
  }
  // Its share of the record: the water of the record's cells that are out, evenly.
  Record& r = found->second;
  settle(r);
  const double part = r.cells_out > 1 ? 1.0 / r.cells_out : 1.0;
  const double share = (r.volume_m3 + r.film_m3) * part;
  r.volume_m3 -= r.volume_m3 * part;
  r.film_m3 -= r.film_m3 * part;
  r.cells_out -= 1;
  if (r.cells_out <= 0) records_.erase(found);
  if (paved_[c]) {
    water_[c] = share / (config_.cell_m * config_.cell_m);
  } else {
    ledger_.drained_m3 += share;  // (none is kept off the road; a guard)
  }
}

void RoadWater::move_to(glm::ivec2 origin) {
  // The track's s near the window's centre, for every cell entering it (project_near refines it).
  const glm::dvec2 centre = (glm::dvec2(origin) + 0.5 * n_) * config_.cell_m;
  const double s_centre = surface_.track().project(centre, 40.0).s;
  if (!placed_) {
    origin_ = origin;
    for (int j = 0; j < n_; ++j) {
      for (int i = 0; i < n_; ++i) fill_cell(i, j, origin_ + glm::ivec2(i, j), s_centre, 0.0);
    }
    placed_ = true;
    return;
  }
  const glm::ivec2 shift = origin - origin_;
  // What the road the window has not seen holds: the mean of the window's paved cells but the
  // puddles (the rain falls there as here; its puddles are its own).
  double sum = 0.0;
  std::size_t counted = 0;
  for (std::size_t c = 0; c < water_.size(); ++c) {
    if (!paved_[c] || state_of(water_[c]) == RoadState::kPuddle) continue;
    sum += water_[c];
    ++counted;
  }
  const double fresh_m = counted > 0 ? sum / static_cast<double>(counted) : 0.0;
  auto inside = [&](glm::ivec2 cell) {  // a window cell index
    return cell.x >= 0 && cell.y >= 0 && cell.x < n_ && cell.y < n_;
  };
  // The cells that leave give their water to the records.
  for (int j = 0; j < n_; ++j) {
    for (int i = 0; i < n_; ++i) {
      if (!inside(glm::ivec2(i, j) - shift)) leave_cell(i, j);
    }
  }
  // The rest move to their new places; the new ones are filled.
  // Into the spare arrays (made once), then swapped in.
  std::vector<double>& ground = spare_ground_;
  std::vector<double>& water = spare_water_;
  std::vector<std::uint8_t>& paved = spare_paved_;
  ground.assign(ground_.size(), 0.0);
  water.assign(water_.size(), 0.0);
  paved.assign(paved_.size(), 0);
  for (int j = 0; j < n_; ++j) {
    for (int i = 0; i < n_; ++i) {
      const glm::ivec2 old = glm::ivec2(i, j) + shift;
      if (!inside(old)) continue;
      const std::size_t from = static_cast<std::size_t>(old.y) * n_ + old.x;
      const std::size_t to = static_cast<std::size_t>(j) * n_ + i;
      ground[to] = ground_[from], water[to] = water_[from];
      paved[to] = paved_[from];
    }
  }
  ground_.swap(ground), water_.swap(water), paved_.swap(paved);
  origin_ = origin;
  for (int j = 0; j < n_; ++j) {
    for (int i = 0; i < n_; ++i) {
      if (!inside(glm::ivec2(i, j) + shift))
        fill_cell(i, j, origin_ + glm::ivec2(i, j), s_centre, fresh_m);
    }
  }
}

void RoadWater::step(glm::dvec2 centre, double rain_mm_h, double dt_s) {
  const glm::ivec2 origin = glm::ivec2(glm::floor(centre / config_.cell_m)) - glm::ivec2(n_ / 2);
  if (!placed_ || origin != origin_) move_to(origin);
  if (!(dt_s > 0.0)) return;
  const double area = config_.cell_m * config_.cell_m;
  const std::size_t count = water_.size();
  const bool raining = rain_mm_h > 0.0;
  time_s_ += dt_s;
  if (!raining) dry_time_s_ += dt_s;

  // Rain in, or evaporation out (the air is saturated while it rains).
  if (raining) {
    const double depth = rain_mm_h / 3.6e6 * dt_s;
    std::size_t paved_cells = 0;
    for (std::size_t c = 0; c < count; ++c) {
      if (!paved_[c]) continue;
      water_[c] += depth;
      ++paved_cells;
    }
    ledger_.rain_in_m3 += depth * area * static_cast<double>(paved_cells);
  } else {
    const double depth = config_.evaporation_m_per_s * dt_s;
    double gone = 0.0;
    for (std::size_t c = 0; c < count; ++c) {
      const double e = std::min(water_[c], depth);
      water_[c] -= e;
      gone += e;
    }
    ledger_.evaporated_m3 += gone * area;
  }

  // Standing water runs to the four neighbours by water level: Manning's sheet flow across each
  // edge, v = h^(2/3) sqrt(slope) / n, from the higher level to the lower, limited to what levels
  // the two cells (a cell never gives more than it has standing: outflows scale down together).
  // A paved cell beside an unpaved one drains into it (the verge lies lower): off the road.
  const double cell = config_.cell_m;
  const double capacity = config_.capacity_m;
  const double inv_n = 1.0 / config_.manning_n;
  auto standing = [&](std::size_t c) { return std::max(water_[c] - capacity, 0.0); };
  // Flow along x from (i, j) to (i + 1, j) and along y from (i, j) to (i, j + 1), m^3 (signed).
  flow_x_.assign(count, 0.0);
  flow_y_.assign(count, 0.0);
  std::fill(outflow_.begin(), outflow_.end(), 0.0);
  auto edge = [&](std::size_t a, std::size_t b) -> double {
    if (!paved_[a] && !paved_[b]) return 0.0;
    const double ha = standing(a), hb = standing(b);
    double level_a = ground_[a] + ha, level_b = ground_[b] + hb;
    if (!paved_[a]) level_a = ground_[b] - kVergeDropM;  // a sink beside b
    if (!paved_[b]) level_b = ground_[a] - kVergeDropM;
    const double dl = level_a - level_b;
    const std::size_t up = dl > 0.0 ? a : b;
    const double h = dl > 0.0 ? ha : hb;
    if (h <= 0.0 || dl == 0.0) return 0.0;
    const double slope = std::abs(dl) / cell;
    const double v = inv_n * std::cbrt(h * h) * std::sqrt(slope);
    // At most what levels them (half the difference each way), or all that stands over a sink.
    const bool to_sink = !paved_[dl > 0.0 ? b : a];
    const double limit = to_sink ? h * area : 0.5 * std::min(std::abs(dl), h) * area;
    const double volume = std::min(v * h * cell * dt_s, limit);
    outflow_[up] += volume;
    return dl > 0.0 ? volume : -volume;
  };
  for (int j = 0; j < n_; ++j) {
    for (int i = 0; i < n_; ++i) {
      const std::size_t c = static_cast<std::size_t>(j) * n_ + i;
      if (i + 1 < n_) flow_x_[c] = edge(c, c + 1);
      if (j + 1 < n_) flow_y_[c] = edge(c, c + n_);
    }
  }
  // Each cell's outflows scaled so that together they take no more than it has standing.
  for (std::size_t c = 0; c < count; ++c) {
    const double have = standing(c) * area;
    outflow_[c] = outflow_[c] > have ? have / outflow_[c] : 1.0;  // now the scale
  }
  double drained = 0.0;
  auto apply = [&](std::size_t a, std::size_t b, double volume) {
    if (volume == 0.0) return;
    const std::size_t up = volume > 0.0 ? a : b, down = volume > 0.0 ? b : a;
    const double moved = std::abs(volume) * outflow_[up];
    water_[up] -= moved / area;
    if (paved_[down]) {
      water_[down] += moved / area;
    } else {
      drained += moved;
    }
  };
  for (int j = 0; j < n_; ++j) {
    for (int i = 0; i < n_; ++i) {
      const std::size_t c = static_cast<std::size_t>(j) * n_ + i;
      if (i + 1 < n_) apply(c, c + 1, flow_x_[c]);
      if (j + 1 < n_) apply(c, c + n_, flow_y_[c]);
    }
  }
  ledger_.drained_m3 += drained;
}

int RoadWater::index(glm::dvec2 xy) const {
  if (!placed_) return -1;
  const glm::ivec2 cell = glm::ivec2(glm::floor(xy / config_.cell_m)) - origin_;
  if (cell.x < 0 || cell.y < 0 || cell.x >= n_ || cell.y >= n_) return -1;
  return cell.y * n_ + cell.x;
}

double RoadWater::water_m(glm::dvec2 xy) const {
  const int c = index(xy);
  return c < 0 ? 0.0 : water_[c];
}

double RoadWater::standing_m(glm::dvec2 xy) const {
  return std::max(water_m(xy) - config_.capacity_m, 0.0);
}

double RoadWater::take(glm::dvec2 xy, double volume_m3) {
  const int c = index(xy);
  if (c < 0 || !(volume_m3 > 0.0)) return 0.0;
  const double area = config_.cell_m * config_.cell_m;
  const double taken = std::min(volume_m3, water_[c] * area);
  water_[c] -= taken / area;
  ledger_.thrown_m3 += taken;
  return taken;
}

void RoadWater::image(RoadWaterImage& out) const {
  out.origin = origin_;
  out.cell_m = config_.cell_m;
  out.cells = n_;
  out.capacity_mm = config_.capacity_m * 1e3;
  out.water_standing_mm.resize(water_.size() * 2);
  out.max_standing_mm = 0.0f;
  double water_sum = 0.0, standing_sum = 0.0;
  int paved = 0;
  for (std::size_t c = 0; c < water_.size(); ++c) {
    const double standing = std::max(water_[c] - config_.capacity_m, 0.0);
    out.water_standing_mm[2 * c] = static_cast<float>(water_[c] * 1e3);
    out.water_standing_mm[2 * c + 1] = static_cast<float>(standing * 1e3);
    out.max_standing_mm = std::max(out.max_standing_mm, static_cast<float>(standing * 1e3));
    if (paved_[c]) {
      water_sum += water_[c];
      standing_sum += standing;
      ++paved;
    }
  }
  // An unpaved cell beside the road shows the water of its paved neighbours, so that the road's
  // edge, drawn smooth, never shows the cells' steps (the verge draws its own wetness).
  for (int j = 0; j < n_; ++j) {
    for (int i = 0; i < n_; ++i) {
      const std::size_t c = static_cast<std::size_t>(j) * n_ + i;
      if (paved_[c]) continue;
      for (const auto& [di, dj] : {std::pair{-1, 0}, {1, 0}, {0, -1}, {0, 1}}) {
        if (i + di < 0 || i + di >= n_ || j + dj < 0 || j + dj >= n_) continue;
        const std::size_t d = static_cast<std::size_t>(j + dj) * n_ + i + di;
        if (!paved_[d]) continue;
        out.water_standing_mm[2 * c] =
            std::max(out.water_standing_mm[2 * c], static_cast<float>(water_[d] * 1e3));
        out.water_standing_mm[2 * c + 1] =
            std::max(out.water_standing_mm[2 * c + 1],
                     static_cast<float>(std::max(water_[d] - config_.capacity_m, 0.0) * 1e3));
      }
    }
  }
  out.mean_water_mm = paved > 0 ? static_cast<float>(water_sum / paved * 1e3) : 0.0f;
  out.mean_standing_mm = paved > 0 ? static_cast<float>(standing_sum / paved * 1e3) : 0.0f;
}

double RoadWater::stored_m3() const {
  double sum = 0.0;
  for (const double w : water_) sum += w;
  sum *= config_.cell_m * config_.cell_m;
  for (const auto& [key, r] : records_) sum += r.volume_m3 + r.film_m3;
  for (const auto& [key, r] : puddle_cells_) sum += r.volume_m3;
  return sum;
}

}  // namespace downpour::sim
