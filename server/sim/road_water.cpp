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
glm::ivec2 coarser(glm::ivec2 cell, int levels_up) {
  return {cell.x >> levels_up, cell.y >> levels_up};  // (C++20: an arithmetic shift, floor)
}

}  // namespace

RoadState road_state(double water_m, const RoadWaterConfig& config) {
  if (water_m < config.wet_m) return RoadState::kDry;
  const double standing = water_m - config.capacity_m;
  return standing < config.drench_m   ? RoadState::kWet
         : standing < config.puddle_m ? RoadState::kDrench
                                      : RoadState::kPuddle;
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
      n_(std::max(48, config.cells / 8 * 8)),
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

void RoadWater::to_record(int level, glm::ivec2 cell, double water, double hollow, bool paved) {
  if (!paved) {
    ledger_.drained_m3 += water * area(level);  // (none stands off the road; a guard)
    return;
  }
  // A paved cell leaves a record even dry: it stays dry, where road never seen takes the mean.
  const glm::ivec2 q = coarser(cell, levels_ - 1 - level);
  auto found = records_.find(Key{q.x, q.y});
  if (found == records_.end()) {
    found =
        records_.emplace(Key{q.x, q.y}, Record{0.0, 0.0, 0.0, 0.0, dry_time_s_, time_s_, rain_m_})
            .first;
  }
  Record& r = found->second;
  settle(r);
  // The texture's water, what the hollows hold (a finest cell's if a puddle) and the film over it.
  const double a = area(level);
  const double standing = std::max(water - config_.capacity_m, 0.0);
  const double held = held_m(water, hollow, level > 0);
  r.texture_m3 += std::min(water, config_.capacity_m) * a;
  r.pooled_m3 += held * a;
  r.film_m3 += (standing - held) * a;
  r.paved_m2 += a;
}

double RoadWater::old_volume(int level, glm::ivec2 cell) const {
  const glm::ivec2 d = cell - old_origins_[level];
  if (d.x < 0 || d.y < 0 || d.x >= n_ || d.y >= n_) return 0.0;  // (never: windows nest)
  const std::size_t c = flat(level, d.x, d.y);
  if (old_owned_[c]) return old_water_[c] * area(level);
  if (level == 0) return 0.0;
  double sum = 0.0;
  for (int k = 0; k < 4; ++k) sum += old_volume(level - 1, 2 * cell + glm::ivec2(k & 1, k >> 1));
  return sum;
}

void RoadWater::share_out(const std::vector<std::size_t>& cells, double volume_m3, double film_m) {
  auto level_of = [&](std::size_t c) { return static_cast<int>(c / layer()); };
  double paved_area = 0.0, hollows = 0.0, deepest = 0.0;
  for (const std::size_t c : cells) {
    if (!paved_[c]) continue;
    const double a = area(level_of(c));
    paved_area += a;
    hollows += hollow_[c] * a;
    deepest = std::max(deepest, hollow_[c]);
  }
  if (paved_area <= 0.0) {
    ledger_.drained_m3 += volume_m3;  // (no paved cell to hold it: it ran off)
    return;
  }
  if (volume_m3 <= 0.0) return;
  const double texture = std::min(config_.capacity_m, volume_m3 / paved_area);
  double rest = volume_m3 - texture * paved_area;
  const double film = std::clamp(rest / paved_area, 0.0, std::max(film_m, 0.0));
  rest -= film * paved_area;
  // The hollows, deepest first: each cell's below the depth t that leaves `pool` in them (found
  // by bisection).
  const double pool = std::clamp(rest, 0.0, hollows);
  auto held = [&](double t) {
    double sum = 0.0;
    for (const std::size_t c : cells)
      if (paved_[c]) sum += std::max(hollow_[c] - t, 0.0) * area(level_of(c));
    return sum;
  };
  double lo = 0.0, hi = deepest;
  if (pool > 0.0) {
    for (int k = 0; k < 50; ++k) {
      const double mid = 0.5 * (lo + hi);
      (held(mid) > pool ? lo : hi) = mid;
    }
  }
  const double t = pool > 0.0 ? hi : deepest;
  // The rest, and what the bisection leaves over (rounding), evenly: the volume is exact.
  const double even = texture + film + (rest - held(t)) / paved_area;
  for (const std::size_t c : cells) {
    if (paved_[c]) water_[c] += even + std::max(hollow_[c] - t, 0.0);
  }
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

// Moving the windows with the car: the first placement fills them
// from the surface; a later one keeps the levels that stay, fills the new cells and hands each
// cell's water on from where the old windows (or the records, or the rain) held it.
void RoadWater::move_to(const std::array<glm::ivec2, kRoadWaterMaxLevels>& origins) {
  if (!placed_) {
    place_first(origins);
    placed_ = true;
    return;
  }
  old_origins_ = origins_;
  origins_ = origins;
  old_ground_.swap(ground_), old_water_.swap(water_), old_places_.swap(places_);
  old_hollow_.swap(hollow_), old_paved_.swap(paved_), old_owned_.swap(owned_);
  const std::size_t count = old_water_.size();
  ground_.assign(count, 0.0), water_.assign(count, 0.0), places_.assign(count, RoadPlace{});
  hollow_.assign(count, 0.0), paved_.assign(count, 0), owned_.assign(count, 0);
  const std::array<bool, kRoadWaterMaxLevels> moved = keep_levels_that_stay();
  const UnseenWater unseen = unseen_water();
  fill_new_cells(moved);
  record_water_left_behind(moved);
  hand_water_on(moved, unseen);
}

void RoadWater::place_first(const std::array<glm::ivec2, kRoadWaterMaxLevels>& origins) {
  const int n = n_;
  origins_ = origins;
  for (int l = 0; l < levels_; ++l) {
    sample_window(l);
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        const glm::ivec2 q = origins[l] + glm::ivec2(i, j);
        const std::size_t c = flat(l, i, j);
        owned_[c] = l == 0 || !inside(origins, l - 1, 2 * q);
        if (owned_[c] && paved_[c] && config_.initial_m > 0.0) {
          water_[c] = config_.initial_m;
          ledger_.rain_in_m3 += config_.initial_m * area(l);
        }
      }
    }
  }
}

std::array<bool, kRoadWaterMaxLevels> RoadWater::keep_levels_that_stay() {
  // A level whose window stays, under a finer one that stays, keeps its cells as they are (the
  // finest windows move most often: most moves leave the coarse ones).
  std::array<bool, kRoadWaterMaxLevels> moved{};
  for (int l = 0; l < levels_; ++l) {
    moved[l] = origins_[l] != old_origins_[l] || (l > 0 && origins_[l - 1] != old_origins_[l - 1]);
    if (moved[l]) continue;
    const std::size_t from = l * layer(), to = (l + 1) * layer();
    std::copy(old_ground_.begin() + from, old_ground_.begin() + to, ground_.begin() + from);
    std::copy(old_water_.begin() + from, old_water_.begin() + to, water_.begin() + from);
    std::copy(old_places_.begin() + from, old_places_.begin() + to, places_.begin() + from);
    std::copy(old_hollow_.begin() + from, old_hollow_.begin() + to, hollow_.begin() + from);
    std::copy(old_paved_.begin() + from, old_paved_.begin() + to, paved_.begin() + from);
    std::copy(old_owned_.begin() + from, old_owned_.begin() + to, owned_.begin() + from);
  }
  return moved;
}

RoadWater::UnseenWater RoadWater::unseen_water() const {
  const std::size_t count = old_water_.size();
  // What the road the windows never saw holds: the rain fell there as here, so the mean (by area)
  // of the paved cells, and of the film running over their hollows (the films shared out below).
  double sum = 0.0, film_sum = 0.0, counted = 0.0;
  for (std::size_t c = 0; c < count; ++c) {
    if (!old_owned_[c] || !old_paved_[c]) continue;
    const double a = area(static_cast<int>(c / layer()));
    sum += old_water_[c] * a;
    const double standing = std::max(old_water_[c] - config_.capacity_m, 0.0);
    film_sum += (standing - held_m(old_water_[c], old_hollow_[c], c >= layer())) * a;
    counted += a;
  }
  if (counted <= 0.0) return {};
  return {sum / counted, film_sum / counted};
}

void RoadWater::fill_new_cells(const std::array<bool, kRoadWaterMaxLevels>& moved) {
  const int n = n_;
  const std::array<glm::ivec2, kRoadWaterMaxLevels>& origins = origins_;
  // The new windows' cells: their ground from the old windows' where they were in them, else from
  // the surface (the guess from the nearest old cell); which of them hold their place's water.
  for (int l = 0; l < levels_; ++l) {
    if (!moved[l]) continue;
    // A window that jumped (a simulator may place the car anywhere) has no old cell near its new
    // ones to start from: all of it from the surface.
    const glm::ivec2 shift = glm::abs(origins[l] - old_origins_[l]);
    const bool jumped = std::max(shift.x, shift.y) > n / 4;
    if (jumped) sample_window(l);
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        const glm::ivec2 q = origins[l] + glm::ivec2(i, j);
        const std::size_t c = flat(l, i, j);
        owned_[c] = l == 0 || !inside(origins, l - 1, 2 * q);
        if (jumped) continue;
        const glm::ivec2 d = q - old_origins_[l];
        const glm::ivec2 near = glm::clamp(d, glm::ivec2(0), glm::ivec2(n - 1));
        const std::size_t oc = flat(l, near.x, near.y);
        if (near == d) {
          ground_[c] = old_ground_[oc], paved_[c] = old_paved_[oc], places_[c] = old_places_[oc];
          hollow_[c] = old_hollow_[oc];
        } else {
          sample(l, q, c, old_places_[oc]);
        }
      }
    }
  }
}

void RoadWater::record_water_left_behind(const std::array<bool, kRoadWaterMaxLevels>& moved) {
  const int n = n_;
  const std::array<glm::ivec2, kRoadWaterMaxLevels>& origins = origins_;
  // The old windows' water that no new window holds goes to the records (before any record is
  // shared out below: those are others). (A level that stays lies in the last window.)
  for (int l = 0; l < levels_; ++l) {
    if (!moved[l]) continue;
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        const std::size_t oc = flat(l, i, j);
        const glm::ivec2 q = old_origins_[l] + glm::ivec2(i, j);
        if (old_owned_[oc] && !inside(origins, levels_ - 1, coarser(q, levels_ - 1 - l)))
          to_record(l, q, old_water_[oc], old_hollow_[oc], old_paved_[oc]);
      }
    }
  }
}

void RoadWater::hand_water_on(const std::array<bool, kRoadWaterMaxLevels>& moved,
                              const UnseenWater& unseen) {
  const int n = n_;
  const std::array<glm::ivec2, kRoadWaterMaxLevels>& origins = origins_;
  const double fresh_m = unseen.fresh_m, film_m = unseen.film_m;
  // Each new cell that holds its place's water takes it from where the old windows held it: the
  // same cell, the finer cells a ring held (their sum), or a share of the coarser cell or record
  // that held it (shared out below, among all the cells it goes to).
  for (int l = 0; l < levels_; ++l) {
    if (!moved[l]) continue;
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        const std::size_t c = flat(l, i, j);
        if (!owned_[c]) continue;
        const glm::ivec2 q = origins[l] + glm::ivec2(i, j);
        if (inside(old_origins_, l, q)) {
          const glm::ivec2 d = q - old_origins_[l];
          const std::size_t oc = flat(l, d.x, d.y);
          if (old_owned_[oc]) {
            water_[c] = old_water_[oc];
            continue;
          }
          double volume = 0.0;
          for (int k = 0; k < 4; ++k)
            volume += old_volume(l - 1, 2 * q + glm::ivec2(k & 1, k >> 1));
          if (paved_[c]) {
            water_[c] = volume / area(l);
          } else {
            ledger_.drained_m3 += volume;
          }
          continue;
        }
        Source source{-1, coarser(q, levels_ - 1 - l)};
        for (int k = l + 1; k < levels_; ++k) {
          if (inside(old_origins_, k, coarser(q, k - l))) {
            source = {k, coarser(q, k - l)};
            break;
          }
        }
        shares_[source].push_back(c);
      }
    }
  }
  for (auto& [source, cells] : shares_) {
    const glm::ivec2 d =
        source.level >= 0 ? source.cell - old_origins_[source.level] : glm::ivec2(0);
    const bool from_cell = source.level >= 0 && old_paved_[flat(source.level, d.x, d.y)];
    if (from_cell) {
      const std::size_t oc = flat(source.level, d.x, d.y);
      const double w = old_water_[oc];
      // Its film over its hollows spreads evenly, what they hold goes to the finer cells' hollows.
      share_out(cells, w * area(source.level),
                std::max(w - config_.capacity_m, 0.0) - held_m(w, old_hollow_[oc], true));
      continue;
    }
    const auto found =
        source.level < 0 ? records_.find(Key{source.cell.x, source.cell.y}) : records_.end();
    if (found != records_.end()) {
      settle(found->second);
      const Record& r = found->second;
      share_out(cells, r.texture_m3 + r.film_m3 + r.pooled_m3,
                r.paved_m2 > 0.0 ? r.film_m3 / r.paved_m2 : 0.0);
      records_.erase(found);
      continue;
    }
    // Rain fell here before the windows came (or on the paved part of a coarse cell whose centre
    // lies off the road, which holds no water): as much as the rings' cells hold, its film spread
    // and the rest in its hollows (it enters the ledger as rain now).
    if (fresh_m <= 0.0) continue;
    double paved_area = 0.0;
    for (const std::size_t c : cells)
      if (paved_[c]) paved_area += area(static_cast<int>(c / layer()));
    ledger_.rain_in_m3 += fresh_m * paved_area;
    share_out(cells, fresh_m * paved_area, film_m);
  }
  shares_.clear();
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
