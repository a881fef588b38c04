#include "server/sim/water.hpp"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>

namespace downpour::sim {
namespace {

constexpr double kGravity = 9.81;        // m/s^2
constexpr double kAirDensity = 1.2;      // kg/m^3
constexpr double kN0 = 8000.0;           // Marshall-Palmer, m^-3 mm^-1
constexpr int kRainBins = 24;            // drop-size bins for the impact rate
constexpr int kRepulsionIterations = 4;  // at most, per step; stops once nothing overlaps

// The eight neighbour steps, counter-clockwise from +u.
constexpr int kStepU[8] = {1, 1, 0, -1, -1, -1, 0, 1};
constexpr int kStepV[8] = {0, 1, 1, 1, 0, -1, -1, -1};

glm::dvec2 direction(float angle_rad) { return {std::cos(angle_rad), std::sin(angle_rad)}; }
glm::dvec2 left_normal(glm::dvec2 d) { return {-d.y, d.x}; }

// Airflow along the glass (u, v), m/s: the relative air's component in the glass plane, slowed
// to what reaches the drops in the boundary layer.
glm::dvec2 airflow_on_glass(const WindshieldConfig& c, const WaterInputs& in) {
  const glm::dvec3 a = in.air_velocity_mps;
  return c.water.airflow_fraction *
         glm::dvec2(glm::dot(a, c.glass.u_axis()), glm::dot(a, c.glass.v_axis()));
}

// A spherical cap of contact radius a and contact angle q holds pi a^3 t (3 + t^2) / 6 of water,
// t = tan(q / 2); seen along the glass it is a circular segment of the sphere (radius a / sin q)
// over the angle 2q.
const double kCapVolumePerCubedRadius = [] {
  const double t = std::tan(0.5 * kContactAngleDeg * M_PI / 180.0);
  return M_PI * t * (3.0 + t * t) / 6.0;
}();
const double kCapFrontalAreaPerSquaredRadius = [] {
  const double q = kContactAngleDeg * M_PI / 180.0, sphere = 1.0 / std::sin(q);
  return 0.5 * sphere * sphere * (2.0 * q - std::sin(2.0 * q));
}();

}  // namespace

double drop_radius_mm(double mass_mg) {
  return std::cbrt(std::max(mass_mg, 0.0) / kCapVolumePerCubedRadius);
}
double drop_mass_mg(double radius_mm) {
  return kCapVolumePerCubedRadius * radius_mm * radius_mm * radius_mm;
}
double drop_frontal_area_mm2(double radius_mm) {
  return kCapFrontalAreaPerSquaredRadius * radius_mm * radius_mm;
}
double terminal_speed_mps(double d_mm) {
  return std::max(0.0, 9.65 - 10.3 * std::exp(-0.6 * d_mm));
}

WaterSim::WaterSim(const WindshieldConfig& config, std::uint64_t seed)
    : config_(config), rain_random_(seed, 1), move_random_(seed, 2), blade_random_(seed, 3) {
  const WaterConfig& w = config_.water;
  const GlassConfig& g = config_.glass;
  cells_u_ = static_cast<int>(std::ceil(g.bottom_width_mm / w.cell_mm));
  cells_v_ = static_cast<int>(std::ceil(g.height_mm / w.cell_mm));
  RandomStream affinity_random(seed, 0);
  affinity_.resize(static_cast<std::size_t>(cells_u_) * cells_v_);
  for (float& a : affinity_) a = static_cast<float>(affinity_random.uniform(w.affinity_min, 1.0));
  cell_drop_.assign(affinity_.size(), -1);
  particle_mass_ = drop_mass_mg(w.particle_radius_mm);
  // Gravity along the glass (the car level); the pinning force that it just overcomes at the
  // critical radius, per millimetre of radius (pinning grows with the contact line).
  const double along = kGravity * std::cos(g.rake_deg * M_PI / 180.0);
  gravity_ = {0.0, -along};
  pin_per_mm_ = drop_mass_mg(w.critical_radius_mm) * 1e-6 * along / w.critical_radius_mm;
  for (int b = 0; b < 2; ++b) {  // parked until the first step says otherwise
    const BladeConfig& c = config_.wipers.blades[b];
    blades_[b] = {glm::vec2(c.pivot_mm), static_cast<float>(c.park_deg * M_PI / 180.0),
                  static_cast<float>(c.length_mm), static_cast<float>(c.width_mm)};
  }
}

int WaterSim::cell_index(glm::dvec2 p) const {
  const int u = static_cast<int>(std::floor(p.x / config_.water.cell_mm));
  const int v = static_cast<int>(std::floor(p.y / config_.water.cell_mm));
  if (u < 0 || v < 0 || u >= cells_u_ || v >= cells_v_) return -1;
  return v * cells_u_ + u;
}

double WaterSim::affinity_at(glm::dvec2 p) const {
  const int c = cell_index(p);
  return c < 0 ? config_.water.affinity_min : affinity_[c];
}

int WaterSim::drop_at(glm::dvec2 p) const {
  const int c = cell_index(p);
  return c < 0 ? -1 : cell_drop_[c];
}

double WaterSim::mass_on_glass() const {
  double m = 0.0;
  for (const Drop& d : drops_) {
    if (d.alive) m += d.mass;
  }
  for (const Particle& p : particles_) m += p.mass;
  return m + carried_[0] + carried_[1];
}

void WaterSim::set_mass(Drop& d, double mass) {
  d.mass = mass;
  d.radius = drop_radius_mm(mass);
}

int WaterSim::new_drop(glm::dvec2 pos, double mass) {
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
  ++drop_count_;
  return i;
}

void WaterSim::remove_drop(int i) {
  Drop& d = drops_[i];
  const int c = cell_index(d.pos);
  if (c >= 0 && cell_drop_[c] == i) cell_drop_[c] = -1;
  d.alive = false;
  free_drops_.push_back(i);
  --drop_count_;
}

void WaterSim::fuse_into(int target, double mass) {
  Drop& d = drops_[target];
  set_mass(d, d.mass + mass);
  d.trail = false;  // a trail drop that gathers water is an ordinary drop again
}

// Drops whose contact circles touch run together: the smaller joins the larger, which stays
// where it is. Trail drops keep out of this (they sit right behind their drop); they join
// only what moves into their cell. Returns the index of the drop that holds i's water.
int WaterSim::coalesce(int i) {
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
    remove_drop(gone);
    i = keep;
  }
}

bool WaterSim::add_drop(glm::dvec2 pos, double mass, bool with_sub_metaballs) {
  if (!on_glass(pos) || mass <= 0.0) return false;
  ledger_.arrived += mass;
  place_drop(pos, mass, with_sub_metaballs);
  return true;
}

void WaterSim::place_drop(glm::dvec2 pos, double mass, bool with_sub_metaballs) {
  const int c = cell_index(pos);
  if (cell_drop_[c] >= 0) {
    fuse_into(cell_drop_[c], mass);
    coalesce(cell_drop_[c]);
    return;
  }
  const int i = new_drop(pos, mass);
  if (with_sub_metaballs) {
    Drop& d = drops_[i];
    d.subs = std::min(config_.water.impact_sub_metaballs, 3);
    const double a0 = rain_random_.uniform(0.0, 2.0 * M_PI);
    for (int k = 0; k < d.subs; ++k) {
      const double a = a0 + 2.0 * M_PI * k / d.subs + rain_random_.uniform(-0.5, 0.5);
      d.sub_dir[k] = glm::vec2(std::cos(a), std::sin(a));
    }
  }
  coalesce(i);
}

void WaterSim::add_particle(glm::dvec2 pos, double mass) {
  ledger_.arrived += mass;
  particles_.push_back({pos, mass, 0.0});
}

glm::dvec2 WaterSim::drive_per_pin(double r, const WaterInputs& in) const {
  const glm::dvec2 air = airflow_on_glass(config_, in);
  const double mass_kg = drop_mass_mg(r) * 1e-6;
  const double area_m2 = drop_frontal_area_mm2(r) * 1e-6;
  const glm::dvec2 drag =
      0.5 * kAirDensity * config_.water.airflow_coefficient * area_m2 * glm::length(air) * air;
  return (mass_kg * gravity_ + drag) / (pin_per_mm_ * std::max(r, 1e-6));
}

void WaterSim::step(double dt, const WaterInputs& in) {
  air_ = airflow_on_glass(config_, in);
  air_spread_ = config_.water.airflow_spread * glm::length(air_);
  blades_ = in.blades_after;
  rain(dt, in);
  move_drops(dt, in);
  sweep_blades(in);
  repel_particles();
  release_particles(dt, in);
}

// Impacts per second = sum over drop sizes of number density x speed through the glass x area
// (TECHNIQUES.md "Rain arrival from physics"), Marshall-Palmer sizes.
void WaterSim::rain(double dt, const WaterInputs& in) {
  const WaterConfig& w = config_.water;
  const GlassConfig& g = config_.glass;
  if (in.rain_rate_mm_h <= 0.0) return;
  const double lambda = 4.1 * std::pow(in.rain_rate_mm_h, -0.21);
  const double area_m2 = 0.5 * (g.bottom_width_mm + g.top_width_mm) * g.height_mm * 1e-6;
  const glm::dvec3 n = g.normal();
  const double bin = (w.max_drop_diameter_mm - w.min_drop_diameter_mm) / kRainBins;
  std::array<double, kRainBins> cumulative{};
  double total = 0.0;
  for (int k = 0; k < kRainBins; ++k) {
    const double d = w.min_drop_diameter_mm + (k + 0.5) * bin;
    const glm::dvec3 velocity = in.air_velocity_mps - glm::dvec3(0.0, 0.0, terminal_speed_mps(d));
    const double flux = std::max(0.0, -glm::dot(velocity, n));  // m/s into the glass
    total += kN0 * std::exp(-lambda * d) * bin * flux * area_m2;
    cumulative[k] = total;
  }
  const std::uint32_t impacts = rain_random_.poisson(total * dt);
  for (std::uint32_t i = 0; i < impacts; ++i) {
    const double pick = rain_random_.uniform() * total;
    const int k = static_cast<int>(std::lower_bound(cumulative.begin(), cumulative.end(), pick) -
                                   cumulative.begin());
    const double d =
        w.min_drop_diameter_mm + (std::min(k, kRainBins - 1) + rain_random_.uniform()) * bin;
    glm::dvec2 pos;
    do {
      pos = {rain_random_.uniform(0.0, g.bottom_width_mm), rain_random_.uniform(0.0, g.height_mm)};
    } while (!on_glass(pos));
    add_drop(pos, M_PI / 6.0 * d * d * d, true);
  }
}

void WaterSim::move_drops(double dt, const WaterInputs& in) {
  const WaterConfig& w = config_.water;
  // Below this radius no drop can flow: |r^2 G + r A| <= r^2 |G| + r |A| < 1.
  const glm::dvec2 unit_g = drive_per_pin(1.0, WaterInputs{});  // gravity alone at r = 1 mm
  const glm::dvec2 with_air = drive_per_pin(1.0, in);
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
        ledger_.evaporated += d.mass;
        remove_drop(static_cast<int>(i));
      } else {
        const double mass = d.trail_mass0 * left * left * left;
        ledger_.evaporated += d.mass - mass;
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
void WaterSim::move_drop(int i, double dt) {
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
  const double sector = std::atan2(dir.y, dir.x) / (M_PI / 4.0);
  const int main = (static_cast<int>(std::lround(sector)) % 8 + 8) % 8;
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
    const double trail = w.trail_fraction * drops_[i].mass;
    if (trail >= w.trail_min_mass_mg) {
      set_mass(drops_[i], drops_[i].mass - trail);
      const int t = new_drop(from, trail);  // may reallocate drops_
      drops_[t].trail = true;
      drops_[t].trail_mass0 = trail;
      drops_[t].trail_radius0 = drops_[t].radius;
    }
    if (!on_glass(to)) {
      ledger_.drained += drops_[i].mass;
      drops_[i].alive = false;
      free_drops_.push_back(i);
      --drop_count_;
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
      --drop_count_;
      coalesce(other);
      return;
    }
    drops_[i].pos = to;
    cell_drop_[to_cell] = i;
    const int now = coalesce(i);
    if (now != i) return;  // it ran into a larger drop
  }
}

// Blades push particles along their normal and turn the mesh drops they touch into particles.
// The test is continuous: a point ahead of the blade before the step and within reach of it after
// was swept, however far the blade turned.
void WaterSim::sweep_blades(const WaterInputs& in) {
  const WaterConfig& w = config_.water;
  const double rp = w.particle_radius_mm;
  for (int b = 0; b < 2; ++b) {
    const BladePose& before = in.blades_before[b];
    const BladePose& after = in.blades_after[b];
    const double turn = after.angle_rad - before.angle_rad;
    if (turn == 0.0) continue;
    const double side = turn > 0.0 ? 1.0 : -1.0;
    const glm::dvec2 pivot(after.pivot_mm);
    const glm::dvec2 d0 = direction(before.angle_rad), d1 = direction(after.angle_rad);
    const glm::dvec2 n0 = side * left_normal(d0), n1 = side * left_normal(d1);
    const double half = 0.5 * after.width_mm, length = after.length_mm;
    auto swept = [&](glm::dvec2 p, double r, double* along) {
      const glm::dvec2 rel = p - pivot;
      *along = glm::dot(d1, rel);
      if (*along < 0.0 || *along > length) return false;
      return glm::dot(n0, rel) >= -half && glm::dot(n1, rel) < half + r;
    };
    double along;
    for (Particle& p : particles_) {
      if (swept(p.pos, rp, &along)) p.pos = pivot + along * d1 + (half + rp) * n1;
    }
    // The swept sector's bounding box (the arc between the tips bulges out to the tip of the
    // middle direction, reached at length / cos(half the turn)), for a quick rejection.
    const glm::dvec2 mid = direction(0.5f * (before.angle_rad + after.angle_rad));
    const glm::dvec2 bulge = pivot + mid * (length / std::cos(0.5 * turn));
    const glm::dvec2 tip0 = pivot + d0 * length, tip1 = pivot + d1 * length;
    const glm::dvec2 lo = glm::min(glm::min(pivot, bulge), glm::min(tip0, tip1)) - half;
    const glm::dvec2 hi = glm::max(glm::max(pivot, bulge), glm::max(tip0, tip1)) + half;
    const std::size_t n = drops_.size();
    for (std::size_t i = 0; i < n; ++i) {
      Drop& d = drops_[i];
      if (!d.alive || d.pos.x < lo.x - d.radius || d.pos.y < lo.y - d.radius ||
          d.pos.x > hi.x + d.radius || d.pos.y > hi.y + d.radius ||
          !swept(d.pos, d.radius, &along)) {
        continue;
      }
      // Particles are equal: the drop's water joins what the blade already carries, and whole
      // particles' worth of it come off as particles here (a tiny trail drop alone makes none).
      const double mass = d.mass;
      remove_drop(static_cast<int>(i));
      if (particles_.size() >= w.max_particles) {
        ledger_.wiped_off += mass;
        continue;
      }
      carried_[b] += mass;
      const int count = static_cast<int>(std::floor(carried_[b] / particle_mass_ + 1e-9));
      carried_[b] = std::max(0.0, carried_[b] - count * particle_mass_);
      for (int k = 0; k < count; ++k) {
        // One at the drop, the rest jittered about it, all ahead of the blade; overlaps resolve
        // through repulsion.
        const double jitter_along = k == 0 ? 0.0 : blade_random_.uniform(-rp, rp);
        const double jitter_ahead = k == 0 ? 0.0 : blade_random_.uniform(0.0, 2.0 * rp);
        particles_.push_back({pivot + (along + jitter_along) * d1 + (half + rp + jitter_ahead) * n1,
                              particle_mass_, 0.0});
      }
    }
  }
}

// Pairwise repulsion through a spatial hash: grid cells of one particle diameter, hashed into a
// table about twice the particle count, so the cost follows the particles, not the glass. Each
// iteration works on float copies of the positions sorted by bucket (a counting sort, so the order
// and the result are deterministic): a bucket's particles are one contiguous run.
void WaterSim::repel_particles() {
  const WaterConfig& w = config_.water;
  const float touch = static_cast<float>(2.0 * w.particle_radius_mm);
  const float push = static_cast<float>(0.5 + w.penalty);  // half the overlap, plus the penalty
  const std::uint32_t count = static_cast<std::uint32_t>(particles_.size());
  if (count < 2) return;
  std::uint32_t buckets = 64;
  while (buckets < 2 * count) buckets *= 2;
  const std::uint32_t mask = buckets - 1;
  const float inv_touch = 1.0f / touch;
  auto bucket_of = [&](int cu, int cv) {
    return (static_cast<std::uint32_t>(cu) * 73856093u ^
            static_cast<std::uint32_t>(cv) * 19349663u) &
           mask;
  };
  hash_ids_.resize(count);
  hash_pos_.resize(count);
  hash_cell_.resize(count);
  for (int iteration = 0; iteration < kRepulsionIterations; ++iteration) {
    hash_start_.assign(buckets + 1, 0u);
    for (std::uint32_t i = 0; i < count; ++i) {
      const glm::dvec2 p = particles_[i].pos;
      const glm::ivec2 c(static_cast<int>(std::floor(static_cast<float>(p.x) * inv_touch)),
                         static_cast<int>(std::floor(static_cast<float>(p.y) * inv_touch)));
      hash_cell_[i] = c;
      ++hash_start_[bucket_of(c.x, c.y) + 1];
    }
    for (std::uint32_t b = 1; b <= buckets; ++b) hash_start_[b] += hash_start_[b - 1];
    hash_fill_.assign(hash_start_.begin(), hash_start_.end() - 1);
    for (std::uint32_t i = 0; i < count; ++i) {
      const std::uint32_t slot = hash_fill_[bucket_of(hash_cell_[i].x, hash_cell_[i].y)]++;
      hash_ids_[slot] = i;
      hash_pos_[slot] = glm::vec2(particles_[i].pos);
    }

    bool overlapped = false;
    for (std::uint32_t a = 0; a < count; ++a) {
      const glm::ivec2 c = hash_cell_[hash_ids_[a]];
      std::uint32_t seen[9];
      int seen_count = 0;
      for (int dv = -1; dv <= 1; ++dv) {
        for (int du = -1; du <= 1; ++du) {
          const std::uint32_t b = bucket_of(c.x + du, c.y + dv);
          if (std::find(seen, seen + seen_count, b) != seen + seen_count) continue;  // a collision
          seen[seen_count++] = b;
          for (std::uint32_t k = std::max(hash_start_[b], a + 1); k < hash_start_[b + 1]; ++k) {
            const glm::vec2 delta = hash_pos_[k] - hash_pos_[a];
            const float dist2 = glm::dot(delta, delta);
            if (dist2 >= touch * touch) continue;
            const float dist = std::sqrt(dist2);
            // Coincident particles part along a direction that depends only on their ids.
            const float angle =
                static_cast<float>(hash_ids_[a]) * 2.399f + static_cast<float>(hash_ids_[k]);
            const glm::vec2 dir =
                dist > 1e-6f ? delta / dist : glm::vec2(std::cos(angle), std::sin(angle));
            const glm::vec2 move = (push * (touch - dist)) * dir;
            hash_pos_[a] -= move;
            hash_pos_[k] += move;
            overlapped = true;
          }
        }
      }
    }
    for (std::uint32_t a = 0; a < count; ++a) {
      glm::dvec2& p = particles_[hash_ids_[a]].pos;
      const glm::dvec2 moved(hash_pos_[a]);
      if (moved != glm::dvec2(glm::vec2(p))) p = moved;  // untouched ones keep their precision
    }
    if (!overlapped) break;
  }
}

bool WaterSim::in_any_region(glm::dvec2 p, const std::array<BladePose, 2>& blades) const {
  const WaterConfig& w = config_.water;
  const double margin = w.region_particle_diameters * 2.0 * w.particle_radius_mm;
  for (const BladePose& b : blades) {
    const glm::dvec2 d = direction(b.angle_rad);
    const glm::dvec2 rel = p - glm::dvec2(b.pivot_mm);
    const double along = glm::dot(d, rel), across = glm::dot(left_normal(d), rel);
    if (along >= 0.0 && along <= b.length_mm && std::abs(across) <= 0.5 * b.width_mm + margin)
      return true;
  }
  return false;
}

// Suspension: a particle does not become a mesh drop while a drop at or above the critical size
// is within the search square around its cell (it would fuse into an unnaturally large drop).
bool WaterSim::suspended(glm::dvec2 p) const {
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

void WaterSim::release_particles(double dt, const WaterInputs& in) {
  // Only a moving blade carries a region; a parked one lets its water go.
  std::array<BladePose, 2> active = in.blades_after;
  bool any = false;
  for (int b = 0; b < 2; ++b) {
    if (in.blades_after[b].angle_rad == in.blades_before[b].angle_rad) {
      active[b].length_mm = -1.0;  // no region
    } else {
      any = true;
    }
  }
  std::size_t kept = 0;
  for (std::size_t i = 0; i < particles_.size(); ++i) {
    const Particle p = particles_[i];
    if (!on_glass(p.pos)) {
      ledger_.wiped_off += p.mass;
      continue;
    }
    if (any && in_any_region(p.pos, active)) {
      particles_[kept++] = {p.pos, p.mass, 0.0};
      continue;
    }
    if (p.held_s < config_.water.suspension_max_s && suspended(p.pos)) {
      particles_[kept++] = {p.pos, p.mass, p.held_s + dt};
      continue;
    }
    place_drop(p.pos, p.mass, false);
  }
  particles_.resize(kept);
}

void WaterSim::publish(WindshieldState& out) const {
  const WaterConfig& w = config_.water;
  const GlassConfig& g = config_.glass;
  out.metaballs.clear();
  out.metaballs.reserve(drop_count_ * 2 + particles_.size());
  auto add = [&](glm::dvec2 p, double r) {
    out.metaballs.push_back(
        {static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(r)});
  };
  for (const Drop& d : drops_) {
    if (!d.alive) continue;
    add(d.pos, d.radius);
    if (d.subs > 0) {
      // Impact sub-metaballs migrate into the main one as they age.
      const double offset =
          (1.0 - d.sub_age / w.sub_metaball_merge_s) * w.sub_metaball_offset * d.radius;
      for (int k = 0; k < d.subs; ++k)
        add(d.pos + offset * glm::dvec2(d.sub_dir[k]), w.sub_metaball_radius * d.radius);
    }
    if (d.moving) add(d.pos - 0.9 * d.radius * d.heading, 0.7 * d.radius);  // a running drop's tail
  }
  for (const Particle& p : particles_) add(p.pos, drop_radius_mm(p.mass));
  out.blades = blades_;
  out.drops = drop_count_;
  out.particles = static_cast<std::uint32_t>(particles_.size());

  // Coverage on a coarse grid: the area each metaball wets (its 0.5 level, radius R) is added to
  // the cells it covers, capped at the cell (overlaps count once only within a small drop).
  const double cell = out.coverage_cell_mm;
  out.coverage_width = static_cast<int>(std::ceil(g.bottom_width_mm / cell));
  out.coverage_height = static_cast<int>(std::ceil(g.height_mm / cell));
  std::vector<float> area(static_cast<std::size_t>(out.coverage_width) * out.coverage_height, 0.0f);
  const float cell_area = static_cast<float>(cell * cell);
  for (const Metaball& m : out.metaballs) {
    const int u0 = static_cast<int>(std::floor((m.u_mm - m.radius_mm) / cell));
    const int u1 = static_cast<int>(std::floor((m.u_mm + m.radius_mm) / cell));
    const int v0 = static_cast<int>(std::floor((m.v_mm - m.radius_mm) / cell));
    const int v1 = static_cast<int>(std::floor((m.v_mm + m.radius_mm) / cell));
    if (u0 == u1 && v0 == v1) {  // within one cell
      if (u0 >= 0 && v0 >= 0 && u0 < out.coverage_width && v0 < out.coverage_height) {
        area[v0 * out.coverage_width + u0] += static_cast<float>(M_PI) * m.radius_mm * m.radius_mm;
      }
      continue;
    }
    for (int v = std::max(v0, 0); v <= std::min(v1, out.coverage_height - 1); ++v) {
      for (int u = std::max(u0, 0); u <= std::min(u1, out.coverage_width - 1); ++u) {
        const float du = static_cast<float>((u + 0.5) * cell) - m.u_mm;
        const float dv = static_cast<float>((v + 0.5) * cell) - m.v_mm;
        if (du * du + dv * dv <= m.radius_mm * m.radius_mm)
          area[v * out.coverage_width + u] += cell_area;
      }
    }
  }
  out.coverage.assign(area.size(), 0);
  std::size_t glass_cells = 0;
  double wet = 0.0;
  for (int v = 0; v < out.coverage_height; ++v) {
    for (int u = 0; u < out.coverage_width; ++u) {
      if (!g.contains({(u + 0.5) * cell, (v + 0.5) * cell})) continue;
      ++glass_cells;
      const std::size_t k = static_cast<std::size_t>(v) * out.coverage_width + u;
      const double fraction = std::min(1.0, static_cast<double>(area[k] / cell_area));
      out.coverage[k] = static_cast<std::uint8_t>(std::lround(255.0 * fraction));
      wet += fraction;
    }
  }
  out.glass_wet_fraction = glass_cells ? wet / glass_cells : 0.0;
}

}  // namespace downpour::sim
