#include "server/sim/mesh_model.hpp"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

#include "server/sim/drop_physics.hpp"

namespace downpour::sim {
namespace {

constexpr double kGravity = 9.81;    // m/s^2
constexpr double kAirDensity = 1.2;  // kg/m^3

// The eight neighbour steps, counter-clockwise from +u.
constexpr int kStepU[8] = {1, 1, 0, -1, -1, -1, 0, 1};
constexpr int kStepV[8] = {0, 1, 1, 1, 0, -1, -1, -1};

// The one of the eight neighbour steps nearest in direction to d (sectors 45 degrees wide,
// centred on the steps), without trigonometry.
int nearest_step(glm::dvec2 d) {
  constexpr double kTan22_5 = 0.41421356237309503;
  const double ax = std::abs(d.x), ay = std::abs(d.y);
  if (ay <= kTan22_5 * ax) return d.x >= 0.0 ? 0 : 4;
  if (ax <= kTan22_5 * ay) return d.y >= 0.0 ? 2 : 6;
  if (d.x >= 0.0) return d.y >= 0.0 ? 1 : 7;
  return d.y >= 0.0 ? 3 : 5;
}

}  // namespace

MeshModel::MeshModel(const WindshieldConfig& config, std::uint64_t seed)
    : config_(config), move_random_(seed, 2) {
  const WaterConfig& w = config_.water;
  const GlassConfig& g = config_.glass;
  cells_u_ = static_cast<int>(std::ceil(g.bottom_width_mm / w.cell_mm));
  cells_v_ = static_cast<int>(std::ceil(g.height_mm / w.cell_mm));
  RandomStream affinity_random(seed, 0);
  affinity_.resize(static_cast<std::size_t>(cells_u_) * cells_v_);
  for (float& a : affinity_) a = static_cast<float>(affinity_random.uniform(w.affinity_min, 1.0));
  cell_drop_.assign(affinity_.size(), -1);
  // Gravity along the glass (the car level); the pinning force that it just overcomes at the
  // critical radius, per millimetre of radius (pinning grows with the contact line).
  const double along = kGravity * std::cos(g.rake_deg * M_PI / 180.0);
  gravity_ = {0.0, -along};
  pin_per_mm_ = drop_mass_mg(w.critical_radius_mm) * 1e-6 * along / w.critical_radius_mm;
}

int MeshModel::cell_index(glm::dvec2 p) const {
  const int u = static_cast<int>(std::floor(p.x / config_.water.cell_mm));
  const int v = static_cast<int>(std::floor(p.y / config_.water.cell_mm));
  if (u < 0 || v < 0 || u >= cells_u_ || v >= cells_v_) return -1;
  return v * cells_u_ + u;
}

double MeshModel::affinity_at(glm::dvec2 p) const {
  const int c = cell_index(p);
  return c < 0 ? config_.water.affinity_min : affinity_[c];
}

int MeshModel::drop_at(glm::dvec2 p) const {
  const int c = cell_index(p);
  return c < 0 ? -1 : cell_drop_[c];
}

void MeshModel::drops_within(std::span<const glm::dvec2> outline, std::vector<int>& out) const {
  out.clear();
  if (outline.empty()) return;
  // A polygon with a corner at no finite place holds what it may: every drop.
  for (const glm::dvec2& p : outline) {
    if (std::isfinite(p.x) && std::isfinite(p.y)) continue;
    for (std::size_t i = 0; i < drops_.size(); ++i) {
      if (drops_[i].alive) out.push_back(static_cast<int>(i));
    }
    return;
  }
  const double cell = config_.water.cell_mm;
  // The cell at x along an axis of `cells`, as a double clamped to just past the grid before it
  // becomes an int (a blade turning half a circle in a step reaches metres, past an int's range).
  auto at = [cell](double x, int cells) {
    return static_cast<int>(std::clamp(std::floor(x / cell), -1.0, static_cast<double>(cells)));
  };
  double y_lo = outline[0].y, y_hi = outline[0].y;
  for (const glm::dvec2& p : outline) y_lo = std::min(y_lo, p.y), y_hi = std::max(y_hi, p.y);
  const int v0 = std::max(0, at(y_lo, cells_v_));
  const int v1 = std::min(cells_v_ - 1, at(y_hi, cells_v_));
  const std::size_t n = outline.size();
  for (int v = v0; v <= v1; ++v) {
    // The polygon's extremes across the row's band: its corners within the band, and where its
    // edges cross the band's lines (a centre on a cell's upper line lies in the next row).
    const double a = v * cell, b = (v + 1) * cell;
    double x_lo = HUGE_VAL, x_hi = -HUGE_VAL;
    for (std::size_t k = 0; k < n; ++k) {
      const glm::dvec2 p = outline[k], q = outline[(k + 1) % n];
      if (p.y >= a && p.y <= b) x_lo = std::min(x_lo, p.x), x_hi = std::max(x_hi, p.x);
      for (const double y : {a, b}) {
        if ((p.y < y) != (q.y < y)) {
          const double x = p.x + (q.x - p.x) * ((y - p.y) / (q.y - p.y));
          x_lo = std::min(x_lo, x), x_hi = std::max(x_hi, x);
        }
      }
    }
    if (x_hi < x_lo) continue;
    const int u0 = std::max(0, at(x_lo, cells_u_));
    const int u1 = std::min(cells_u_ - 1, at(x_hi, cells_u_));
    const std::int32_t* row = cell_drop_.data() + static_cast<std::size_t>(v) * cells_u_;
    for (int u = u0; u <= u1; ++u) {
      if (row[u] >= 0) out.push_back(row[u]);
    }
  }
  std::sort(out.begin(), out.end());
}

double MeshModel::mass() const {
  double m = 0.0;
  for (const Drop& d : drops_) {
    if (d.alive) m += d.mass;
  }
  return m;
}

void MeshModel::set_mass(Drop& d, double mass) {
  d.mass = mass;
  d.radius = drop_radius_mm(mass);
  radius_bound_ = std::max(radius_bound_, d.radius);
}

int MeshModel::new_drop(glm::dvec2 pos, double mass) {
  int i;
  if (!free_drops_.empty()) {
    i = free_drops_.back();
    free_drops_.pop_back();
    drops_[i] = Drop{};
  } else {
    i = static_cast<int>(drops_.size());
    drops_.emplace_back();
  }
  Drop& d = drops_[i];
  d.pos = pos;
  d.alive = true;
  set_mass(d, mass);
  cell_drop_[cell_index(pos)] = i;
  ++count_;
  return i;
}

void MeshModel::remove(int i) {
  Drop& d = drops_[i];
  const int c = cell_index(d.pos);
  if (c >= 0 && cell_drop_[c] == i) cell_drop_[c] = -1;
  d.alive = false;
  free_drops_.push_back(i);
  --count_;
}

void MeshModel::fuse_into(int target, double mass) {
  Drop& d = drops_[target];
  set_mass(d, d.mass + mass);
  d.trail = false;  // a trail drop that gathers water is an ordinary drop again
}

// Drops whose contact circles touch run together: the smaller joins the larger, which stays
// where it is. Trail drops keep out of this (they sit right behind their drop); they join
// only what moves into their cell. Returns the index of the drop that holds i's water.
int MeshModel::coalesce(int i) {
  const WaterConfig& w = config_.water;
  for (;;) {
    const Drop& d = drops_[i];
    if (d.trail) return i;
    const int reach = static_cast<int>(std::ceil((d.radius + w.critical_radius_mm) / w.cell_mm));
    const int cu = static_cast<int>(std::floor(d.pos.x / w.cell_mm));
    const int cv = static_cast<int>(std::floor(d.pos.y / w.cell_mm));
    int touching = -1;
    for (int v = std::max(cv - reach, 0); v <= std::min(cv + reach, cells_v_ - 1) && touching < 0;
         ++v) {
      for (int u = std::max(cu - reach, 0); u <= std::min(cu + reach, cells_u_ - 1); ++u) {
        const int j = cell_drop_[v * cells_u_ + u];
        if (j < 0 || j == i || drops_[j].trail) continue;
        const double reach_mm = d.radius + drops_[j].radius;
        const glm::dvec2 delta = drops_[j].pos - d.pos;
        if (glm::dot(delta, delta) < reach_mm * reach_mm) {
          touching = j;
          break;
        }
      }
    }
    if (touching < 0) return i;
    const int keep = drops_[touching].mass > d.mass ? touching : i;
    const int gone = keep == i ? touching : i;
    fuse_into(keep, drops_[gone].mass);
    drops_[keep].travel = std::max(drops_[keep].travel, drops_[gone].travel);
    remove(gone);
    i = keep;
  }
}

void MeshModel::place(glm::dvec2 pos, double mass, RandomStream* sub_metaball_random) {
  const int c = cell_index(pos);
  if (cell_drop_[c] >= 0) {
    fuse_into(cell_drop_[c], mass);
    coalesce(cell_drop_[c]);
    return;
  }
  const int i = new_drop(pos, mass);
  if (sub_metaball_random) {
    Drop& d = drops_[i];
    d.subs = std::min(config_.water.impact_sub_metaballs, 3);
    const double a0 = sub_metaball_random->uniform(0.0, 2.0 * M_PI);
    for (int k = 0; k < d.subs; ++k) {
      const double a = a0 + 2.0 * M_PI * k / d.subs + sub_metaball_random->uniform(-0.5, 0.5);
      d.sub_dir[k] = glm::vec2(std::cos(a), std::sin(a));
    }
  }
  coalesce(i);
}

glm::dvec2 MeshModel::drive_per_pin(double r, glm::dvec2 air) const {
  const double mass_kg = drop_mass_mg(r) * 1e-6;
  const double area_m2 = drop_frontal_area_mm2(r) * 1e-6;
  const glm::dvec2 drag =
      0.5 * kAirDensity * config_.water.airflow_coefficient * area_m2 * glm::length(air) * air;
  return (mass_kg * gravity_ + drag) / (pin_per_mm_ * std::max(r, 1e-6));
}

void MeshModel::step(double dt, glm::dvec2 air) {
  const WaterConfig& w = config_.water;
  air_ = air;
  air_spread_ = w.airflow_spread * glm::length(air_);
  // Below this radius no drop can flow: |r^2 G + r A| <= r^2 |G| + r |A| < 1.
  const glm::dvec2 unit_g = drive_per_pin(1.0, glm::dvec2(0.0));  // gravity alone at r = 1 mm
  const glm::dvec2 with_air = drive_per_pin(1.0, air);
  const double g1 = glm::length(unit_g), a1 = glm::length(with_air - unit_g);
  const double r_min = (-a1 + std::sqrt(a1 * a1 + 4.0 * g1)) / (2.0 * g1);

  const std::size_t n = drops_.size();  // drops made during this pass move next step
  for (std::size_t i = 0; i < n; ++i) {
    Drop& d = drops_[i];
    if (!d.alive) continue;
    if (d.subs > 0 && (d.sub_age += dt) >= w.sub_metaball_merge_s) d.subs = 0;
    if (d.trail) {
      // Evaporation through the drop's surface: the radius shrinks at a steady rate.
      d.age += dt;
      const double left = 1.0 - d.age / w.trail_lifetime_s;
      if (left <= 0.0) {
        evaporated_ += d.mass;
        remove(static_cast<int>(i));
      } else {
        const double mass = d.trail_mass0 * left * left * left;
        evaporated_ += d.mass - mass;
        d.mass = mass;
        d.radius = d.trail_radius0 * left;
      }
      continue;
    }
    if (d.radius < r_min) {
      d.moving = false;
      continue;
    }
    move_drop(static_cast<int>(i), dt);
  }
}

// The mesh model's step for one drop: its speed from the forces, then one-cell moves to one of
// three neighbours in the direction of motion, chosen at random weighted by affinity, fusing with
// what it meets and leaving a trail.
void MeshModel::move_drop(int i, double dt) {
  const WaterConfig& w = config_.water;
  glm::dvec2 ratio;
  {
    const Drop& d = drops_[i];
    const double mass_kg = d.mass * 1e-6;
    const double area_m2 = drop_frontal_area_mm2(d.radius) * 1e-6;
    // The air parts around the cabin: over the glass it also spreads out towards the pillars.
    const double half = 0.5 * config_.glass.bottom_width_mm;
    const glm::dvec2 air = air_ + glm::dvec2(air_spread_ * (d.pos.x - half) / half, 0.0);
    const glm::dvec2 drag =
        0.5 * kAirDensity * w.airflow_coefficient * area_m2 * glm::length(air) * air;
    ratio = (mass_kg * gravity_ + drag) / (pin_per_mm_ * d.radius);
  }
  const double excess = glm::length(ratio) - 1.0;
  if (excess <= 0.0) {
    drops_[i].moving = false;
    drops_[i].travel = 0.0;
    return;
  }
  const glm::dvec2 dir = ratio / (excess + 1.0);
  const int main = nearest_step(dir);
  drops_[i].moving = true;
  drops_[i].travel += std::min(w.mobility_mm_s * excess, w.max_speed_mm_s) * dt;

  while (drops_[i].travel >= w.cell_mm) {
    const glm::dvec2 from = drops_[i].pos;
    int choice[3] = {(main + 7) % 8, main, (main + 1) % 8};
    double weight[3];
    for (int k = 0; k < 3; ++k) {
      const glm::dvec2 to = from + w.cell_mm * glm::dvec2(kStepU[choice[k]], kStepV[choice[k]]);
      weight[k] = affinity_at(to);
    }
    const double pick = move_random_.uniform() * (weight[0] + weight[1] + weight[2]);
    const int s = choice[pick < weight[0] ? 0 : pick < weight[0] + weight[1] ? 1 : 2];
    const glm::dvec2 step(kStepU[s], kStepV[s]);
    const glm::dvec2 to = from + w.cell_mm * step;
    drops_[i].travel -= w.cell_mm * glm::length(step);
    drops_[i].heading = glm::normalize(step);

    // Leave the cell, with a trail drop behind.
    const int from_cell = cell_index(from);
    cell_drop_[from_cell] = -1;
    const int spacing = std::max(w.trail_spacing_cells, 1);
    const bool leave = ++drops_[i].cells_since_trail >= spacing;
    const double trail = leave ? w.trail_fraction * spacing * drops_[i].mass : 0.0;
    if (leave) drops_[i].cells_since_trail = 0;
    if (leave && trail >= w.trail_min_mass_mg) {
      set_mass(drops_[i], drops_[i].mass - trail);
      const glm::dvec2 run = drops_[i].heading;
      const int t = new_drop(from, trail);  // may reallocate drops_
      drops_[t].heading = run;              // the rivulet's direction (glass_water_surface.hpp)
      drops_[t].trail = true;
      drops_[t].trail_mass0 = trail;
      drops_[t].trail_radius0 = drops_[t].radius;
    }
    if (!on_glass(to)) {
      drained_ += drops_[i].mass;
      drops_[i].alive = false;
      free_drops_.push_back(i);
      --count_;
      return;
    }
    const int to_cell = cell_index(to);
    const int other = cell_drop_[to_cell];
    if (other >= 0) {
      // Fusion: the water joins the drop it meets, which carries on with the remaining motion.
      fuse_into(other, drops_[i].mass);
      Drop& o = drops_[other];
      o.travel = std::max(o.travel, drops_[i].travel);
      o.heading = drops_[i].heading;
      drops_[i].alive = false;
      free_drops_.push_back(i);
      --count_;
      coalesce(other);
      return;
    }
    drops_[i].pos = to;
    cell_drop_[to_cell] = i;
    const int now = coalesce(i);
    if (now != i) return;  // it ran into a larger drop
  }
}

// The suspension search (seed 000, section 1.3): a particle does not become a mesh drop while a
// drop at or above the critical size is within the square around its cell (it would fuse into an
// unnaturally large drop).
bool MeshModel::holds_critical_drop_near(glm::dvec2 p) const {
  const WaterConfig& w = config_.water;
  const int reach = w.suspension_cells / 2;
  const int cu = static_cast<int>(std::floor(p.x / w.cell_mm)),
            cv = static_cast<int>(std::floor(p.y / w.cell_mm));
  for (int v = std::max(cv - reach, 0); v <= std::min(cv + reach, cells_v_ - 1); ++v) {
    for (int u = std::max(cu - reach, 0); u <= std::min(cu + reach, cells_u_ - 1); ++u) {
      const int i = cell_drop_[v * cells_u_ + u];
      if (i >= 0 && drops_[i].radius >= w.critical_radius_mm) return true;
    }
  }
  return false;
}

}  // namespace downpour::sim
