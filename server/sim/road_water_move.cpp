// The water on the road as its windows move with the car (RoadWater::move_to): the first
// placement, the levels that stay, the new cells, and each place's water handed on between the old
// windows, the new ones and the records. The rest of RoadWater is road_water.cpp.
#include "server/sim/road_water.hpp"

#include <algorithm>
#include <vector>

#include <glm/common.hpp>

namespace downpour::sim {

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
        shares_.emplace_back(source, c);
      }
    }
  }
  std::sort(shares_.begin(), shares_.end(), [](const auto& a, const auto& b) {
    return a.first < b.first || (!(b.first < a.first) && a.second < b.second);
  });
  for (std::size_t begin = 0; begin < shares_.size();) {
    const Source source = shares_[begin].first;
    sharing_.clear();
    for (; begin < shares_.size() && !(source < shares_[begin].first); ++begin)
      sharing_.push_back(shares_[begin].second);
    const std::span<const std::size_t> cells(sharing_);
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

void RoadWater::share_out(std::span<const std::size_t> cells, double volume_m3, double film_m) {
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

}  // namespace downpour::sim
