#include "server/sim/spray.hpp"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>

#include "server/sim/car_body.hpp"
#include "server/sim/pose.hpp"
#include "server/sim/road_water.hpp"
#include "server/sim/vehicle_class.hpp"

namespace downpour::sim {
namespace {

constexpr double kGravity = 9.81;
constexpr double kAirDensity = 1.2;       // kg/m^3
constexpr double kAirViscosity = 1.8e-5;  // Pa s
constexpr double kWaterDensity = 1000.0;
constexpr double kDeg = M_PI / 180.0;
// A body's parcels are drawn at least this share of the neighbour radius: parcels of a sheet,
// about half that apart, overlap.
constexpr double kSheetRadius = 0.35;
// The renderer's car is the ego car's shape scaled to a traffic vehicle's size by these.
constexpr double kCarLength = 4.6, kCarWidth = 1.8, kCarHeight = 1.47;

}  // namespace

SprayGround::Probe RoadWaterGround::probe(glm::dvec2 xy) const {
  Probe p;
  const int c = road_.cell_at(xy);
  if (c < 0) {
    p.beyond = true;
    p.water_m = mean_water_m_;
    p.standing_m = mean_standing_m_;
    p.state = road_.state_of(mean_water_m_);
    return p;
  }
  p.water_m = road_.water()[c];
  p.standing_m = std::max(p.water_m - road_.config().capacity_m, 0.0);
  p.state = road_.cell_state(static_cast<std::size_t>(c));
  return p;
}

double RoadWaterGround::take(glm::dvec2 xy, double volume_m3) { return road_.take(xy, volume_m3); }

double RoadWaterGround::give(glm::dvec2 xy, double volume_m3) { return road_.give(xy, volume_m3); }

// A source as the step sees it: its frame, its speed and direction of travel, its size.
struct Spray::Pose {
  std::uint32_t key = 0;
  glm::dvec3 position{0.0};
  glm::dmat3 rotation{1.0};  // vehicle to world
  glm::dvec3 velocity{0.0};
  double speed = 0.0;            // horizontal
  glm::dvec3 travel{1.0, 0, 0};  // horizontal unit, the direction of travel
  glm::dvec3 left{0, 1.0, 0};    // horizontal unit, to its left
  glm::dvec3 scale{1.0};         // of the car's shape to its size
  double height = kCarHeight;
  double rear_x = car_body::kHullRearX;
  // The ground's height under a world point, on the plane of the vehicle's wheels.
  double ground_z(glm::dvec3 p) const {
    const glm::dvec3 n = rotation[2];
    if (n.z < 0.2) return position.z;  // (not on its wheels: a level plane)
    return position.z - (n.x * (p.x - position.x) + n.y * (p.y - position.y)) / n.z;
  }
};

Spray::Spray(std::uint64_t seed, SprayConfig config) : config_(config), random_(seed, 5) {
  // The budget's room at once (a session's memory is taken when it starts, 1.9 MB at 20,000),
  // with a step's births over it.
  particles_.reserve(config_.max_particles + 4096);
  // Drag toward the air (Schiller-Naumann: the Stokes rate times 1 + 0.15 Re^0.687), exact over a
  // step for a constant rate: tabulated by the relative speed for each kind, so that a step takes
  // no pow() or exp() per parcel.
  for (int k = 0; k < kSprayKinds; ++k) {
    const double d = config_.diameter_mm[k] * 1e-3;
    const double stokes = 18.0 * kAirViscosity / (kWaterDensity * d * d);
    for (int i = 0; i <= kDragSteps; ++i) {
      const double re = kAirDensity * (i * kDragSpeedStep) * d / kAirViscosity;
      Drag& g = drag_[k][i];
      g.rate = stokes * (1.0 + 0.15 * std::pow(re, 0.687));
      g.decay = std::exp(-g.rate * config_.step_s);
      g.gone = (1.0 - g.decay) / g.rate;
    }
  }
}

Spray::Drag Spray::drag_at(int kind, double speed) const {
  const double x = std::min(speed / kDragSpeedStep, kDragSteps - 1e-9);
  const int i = static_cast<int>(x);
  const double f = x - i;
  const Drag& a = drag_[kind][i];
  const Drag& b = drag_[kind][i + 1];
  return {a.rate + (b.rate - a.rate) * f, a.decay + (b.decay - a.decay) * f,
          a.gone + (b.gone - a.gone) * f};
}

double Spray::airborne_m3() const {
  double sum = 0.0;
  for (const SprayParticle& p : particles_) sum += p.volume_m3;
  return sum;
}

glm::dvec3 Spray::wake(const Pose& v, glm::dvec3 p, double* strength) const {
  *strength = 0.0;
  if (v.speed < 0.1) return glm::dvec3(0.0);
  const glm::dvec3 local = glm::transpose(v.rotation) * (p - v.position);
  const double behind = v.rear_x - local.x;  // < 0 beside or under the vehicle
  const double length = v.scale.x * kCarLength;
  if (behind < -length) return glm::dvec3(0.0);
  const double d = std::max(behind, 0.0);
  const double half_width = 0.6 * v.scale.y * kCarWidth + 0.1 * d;
  const double across = std::exp(-(local.y * local.y) / (half_width * half_width));
  const double above = std::max(local.z - v.height, 0.0) / (0.5 * v.height);
  const double up_to = std::exp(-above * above);
  const double along = std::exp(-d / (config_.wake_heights * v.height));
  *strength = along * across * up_to;
  glm::dvec3 air = config_.wake_fraction * *strength * v.velocity;
  if (behind > 0.0 && local.z < v.height) {
    air += v.rotation[2] * (config_.upwash_fraction * v.speed * std::exp(-d / v.height) * across);
  }
  return air;
}

void Spray::emit(const Pose& v, SprayGround& ground) {
  const SprayConfig& c = config_;
  const double speed = v.speed;
  if (speed < c.min_speed_mps) return;
  const double dt = c.step_s;
  const double thrown = speed * speed / (speed * speed + c.throw_speed_mps * c.throw_speed_mps);
  const double radius = std::clamp(c.tire_radius_m * v.scale.z, 0.25, 0.6);
  const double width = c.tire_width_m * std::clamp(v.scale.y, 0.8, 1.6);
  const glm::dvec3 up = v.rotation[2];
  const glm::dmat4 to_world = [&] {
    glm::dmat4 m(v.rotation);
    m[3] = glm::dvec4(v.position, 1.0);
    return m;
  }();
  for (int t = 0; t < kTires; ++t) {
    const double side = t % 2 == 0 ? 1.0 : -1.0;  // left tires throw to the left
    const glm::dvec3 contact(to_world * glm::dvec4((t < 2 ? car_body::kWheelbase : 0.0) * v.scale.x,
                                                   side * car_body::kTrackHalfWidth * v.scale.y,
                                                   0.0, 1.0));
    const SprayGround::Probe under = ground.probe(glm::dvec2(contact));
    if (under.state == RoadState::kDry) continue;
    const SprayKind kind = under.state == RoadState::kWet      ? SprayKind::kSmall
                           : under.state == RoadState::kDrench ? SprayKind::kMedium
                                                               : SprayKind::kLarge;
    const double texture = under.water_m - under.standing_m;
    // Flows (m^3/s): what the tread throws, and the sheet a tire in a puddle pushes aside.
    const double tire_flow =
        speed * width * (c.film_share * under.standing_m + c.texture_share * texture) * thrown;
    const double splash_flow = under.state == RoadState::kPuddle
                                   ? speed * width * under.standing_m * c.splash_share * thrown
                                   : 0.0;
    const double fill = 1.0 - std::exp(-tire_flow / c.flow_ref_m3_s);
    const std::uint32_t n_tire = random_.poisson(c.tire_parcels_per_s * fill * dt);
    const std::uint32_t n_mist = random_.poisson(c.mist_parcels_per_s * fill * dt);
    const std::uint32_t n_splash = random_.poisson(
        c.splash_parcels_per_s * (1.0 - std::exp(-splash_flow / c.flow_ref_m3_s)) * dt);
    const std::size_t first = particles_.size();
    double wanted = 0.0;
    // On the arc behind the patch, leaving with the rim's velocity there (the wheel rolls: the
    // rim at angle phi from straight down moves at speed (1 - cos phi) along and sin phi up).
    auto from_tire = [&](SprayKind k, double volume, double slow) {
      const double phi =
          c.peak_deg * kDeg * -std::log(random_.uniform(1e-12, 1.0) * random_.uniform(1e-12, 1.0));
      const double across = random_.uniform(-0.5, 0.5) * width;
      const double keep = random_.uniform(0.75, 1.0) * slow;
      const double out = random_.uniform(0.0, 0.08);
      if (phi > c.mudguard_deg * kDeg) return;  // blocked: it stays on the road
      SprayParticle p;
      p.position_m = contact + up * radius +
                     radius * (-std::sin(phi) * v.travel - std::cos(phi) * up) + v.left * across;
      p.velocity_mps = speed * keep * ((1.0 - std::cos(phi)) * v.travel + std::sin(phi) * up) +
                       v.left * (side * out * speed);
      p.volume_m3 = volume;
      p.source = v.key;
      p.kind = k;
      particles_.push_back(p);
      wanted += volume;
    };
    for (std::uint32_t k = 0; k < n_tire; ++k)
      from_tire(kind, (1.0 - c.mist_share) * tire_flow * dt / n_tire, 1.0);
    for (std::uint32_t k = 0; k < n_mist; ++k)
      from_tire(SprayKind::kMist, c.mist_share * tire_flow * dt / n_mist, 0.6);
    // The splash: at theta from the direction of travel with density sin(2 theta), to both sides.
    for (std::uint32_t k = 0; k < n_splash; ++k) {
      const double theta = 0.5 * std::acos(1.0 - 2.0 * random_.uniform());
      const double to = random_.uniform() < 0.5 ? -1.0 : 1.0;
      const double rise = random_.uniform(10.0, 35.0) * kDeg;
      const double depth = std::min(under.standing_m / 0.01, 1.0);
      const double fast = speed * (0.3 + 0.5 * depth) * random_.uniform(0.7, 1.0);
      const glm::dvec3 dir = std::cos(theta) * v.travel + std::sin(theta) * to * v.left;
      SprayParticle p;
      p.position_m = contact + v.travel * 0.12 + v.left * (to * 0.5 * width) + up * 0.02;
      p.velocity_mps = fast * (std::cos(rise) * dir + std::sin(rise) * up);
      p.volume_m3 = splash_flow * dt / n_splash;
      p.source = v.key;
      p.kind = SprayKind::kLarge;
      p.splash = true;
      particles_.push_back(p);
      wanted += p.volume_m3;
    }
    if (wanted <= 0.0) continue;
    // The water comes from the cell under the tire; a cell that holds less gives what it has.
    const glm::dvec2 at(contact);
    const double got = under.beyond ? wanted : ground.take(at, wanted);
    (under.beyond ? ledger_.beyond_m3 : ledger_.taken_m3) += got;
    const double share = got / wanted;
    for (std::size_t i = first; i < particles_.size(); ++i) {
      SprayParticle& p = particles_[i];
      p.volume_m3 *= share;
      p.gathered_m = static_cast<float>(std::cbrt(3.0 * p.volume_m3 / (4.0 * M_PI)));
    }
  }
}

namespace {
constexpr double kGridCell_m = 8.0;
constexpr int kGridSide = 64;  // cells: 512 m, the ego car's range of 250 m either way
constexpr std::size_t kMaxWetBodies = 1024;
}  // namespace

void Spray::find_targets(const std::vector<SpraySource>& sources, std::size_t first) {
  targets_.clear();
  grid_target_.clear();
  grid_next_.clear();
  grid_head_.assign(static_cast<std::size_t>(kGridSide) * kGridSide, -1);
  if (sources.empty()) return;
  grid_origin_ = glm::dvec2(sources[0].state.position_m) - 0.5 * kGridSide * kGridCell_m;
  for (std::size_t i = first; i < sources.size() && targets_.size() < 4096; ++i) {
    const SpraySource& s = sources[i];
    const VehicleLayout& layout = vehicle_layout(s.vehicle_class);
    const glm::dvec3 size = glm::max(s.size_m, glm::dvec3(0.5));
    const double rear = layout.rear_m * size.x / layout.size_m.x;
    const glm::dmat3 rotation = rotation_matrix(s.state.rotation);
    if (rotation[2].z < 0.5) continue;  // not on its wheels
    const glm::dvec3 box_lo(rear, -0.5 * size.y, 0.1), box_hi(rear + size.x, 0.5 * size.y, size.z);
    const glm::dvec3 centre = s.state.position_m + rotation * (0.5 * (box_lo + box_hi));
    const double reach = 0.5 * std::hypot(size.x, size.y);
    const Target t{s.key,
                   glm::dvec2(centre),
                   reach * reach,
                   s.state.position_m,
                   glm::transpose(rotation),
                   box_lo,
                   box_hi,
                   0.0};
    // Its cells: those its footprint's circle touches.
    const glm::dvec2 lo = (glm::dvec2(centre) - reach - grid_origin_) / kGridCell_m;
    const glm::dvec2 hi = (glm::dvec2(centre) + reach - grid_origin_) / kGridCell_m;
    if (hi.x < 0.0 || hi.y < 0.0 || lo.x >= kGridSide || lo.y >= kGridSide) continue;
    const auto index = static_cast<std::int32_t>(targets_.size());
    targets_.push_back(t);
    for (int y = std::max(0, static_cast<int>(lo.y));
         y <= std::min(kGridSide - 1, static_cast<int>(hi.y)); ++y) {
      for (int x = std::max(0, static_cast<int>(lo.x));
           x <= std::min(kGridSide - 1, static_cast<int>(hi.x)); ++x) {
        std::int32_t& head = grid_head_[static_cast<std::size_t>(y) * kGridSide + x];
        grid_target_.push_back(index);
        grid_next_.push_back(head);
        head = static_cast<std::int32_t>(grid_target_.size() - 1);
      }
    }
  }
}

Spray::Target* Spray::target_at(glm::dvec3 p, std::uint32_t source) {
  const glm::dvec2 g = (glm::dvec2(p) - grid_origin_) / kGridCell_m;
  if (!(g.x >= 0.0 && g.y >= 0.0 && g.x < kGridSide && g.y < kGridSide)) return nullptr;
  const std::size_t cell =
      static_cast<std::size_t>(static_cast<int>(g.y)) * kGridSide + static_cast<int>(g.x);
  for (std::int32_t e = grid_head_[cell]; e >= 0; e = grid_next_[static_cast<std::size_t>(e)]) {
    Target& t = targets_[static_cast<std::size_t>(grid_target_[static_cast<std::size_t>(e)])];
    if (t.key == source) continue;
    const glm::dvec2 d = glm::dvec2(p) - t.centre;
    if (d.x * d.x + d.y * d.y > t.reach2) continue;
    const glm::dvec3 q = t.to_vehicle * (p - t.position);
    if (q.x > t.lo.x && q.x < t.hi.x && q.y > t.lo.y && q.y < t.hi.y && q.z > t.lo.z &&
        q.z < t.hi.z)
      return &t;
  }
  return nullptr;
}

// Each body's water: what it held, run off and dried over the step, and what it caught.
void Spray::wet_bodies() {
  const double keep = std::exp(-config_.step_s / config_.body_dry_s);
  for (auto& [key, water] : body_water_) water *= keep;
  for (const Target& t : targets_) {
    if (t.wet_m3 <= 0.0) continue;
    const auto it =
        std::lower_bound(body_water_.begin(), body_water_.end(), std::make_pair(t.key, 0.0),
                         [](const auto& a, const auto& b) { return a.first < b.first; });
    if (it != body_water_.end() && it->first == t.key)
      it->second += t.wet_m3;
    else
      body_water_.insert(it, {t.key, t.wet_m3});
  }
  // A microlitre is dry. Bounded: past kMaxWetBodies, the driest go.
  std::erase_if(body_water_, [](const auto& b) { return b.second < 1e-9; });
  if (body_water_.size() > kMaxWetBodies) {
    std::vector<double> water;
    for (const auto& b : body_water_) water.push_back(b.second);
    std::nth_element(water.begin(), water.end() - kMaxWetBodies, water.end());
    const double least = water[water.size() - kMaxWetBodies];
    std::erase_if(body_water_, [least](const auto& b) { return b.second < least; });
  }
}

double Spray::body_wetness(std::uint32_t key, glm::dvec3 size_m) const {
  const auto it = std::lower_bound(body_water_.begin(), body_water_.end(), std::make_pair(key, 0.0),
                                   [](const auto& a, const auto& b) { return a.first < b.first; });
  if (it == body_water_.end() || it->first != key) return 0.0;
  const glm::dvec3 s = glm::max(size_m, glm::dvec3(0.5));
  const double area = 2.0 * (s.x * s.y + s.x * s.z + s.y * s.z);
  return std::min(it->second / (area * config_.wet_film_mm * 1e-3), 1.0);
}

void Spray::step(const std::vector<SpraySource>& sources, glm::dvec3 wind, SprayGround& ground,
                 const GlassConfig* glass, const GlassHit& glass_hit) {
  const SprayConfig& c = config_;
  const double dt = c.step_s;
  std::vector<Pose> poses;
  poses.reserve(sources.size());
  for (const SpraySource& s : sources) {
    Pose p;
    p.key = s.key;
    p.position = s.state.position_m;
    p.rotation = rotation_matrix(s.state.rotation);
    p.velocity = s.state.velocity_mps;
    const glm::dvec3 flat(p.velocity.x, p.velocity.y, 0.0);
    p.speed = glm::length(flat);
    const glm::dvec3 forward(p.rotation[0].x, p.rotation[0].y, 0.0);
    p.travel = p.speed > 1e-6 ? flat / p.speed : glm::normalize(forward);
    p.left = glm::dvec3(-p.travel.y, p.travel.x, 0.0);
    const glm::dvec3 size = glm::max(s.size_m, glm::dvec3(0.5));
    p.scale = size / glm::dvec3(kCarLength, kCarWidth, kCarHeight);
    p.height = size.z;
    // Where the flow leaves the body: a car's hull top edge (its bumper sits further back, low),
    // the other classes' square backs.
    const VehicleLayout& layout = vehicle_layout(s.vehicle_class);
    const double rear =
        s.vehicle_class == VehicleClass::kCar ? car_body::kHullRearX : layout.rear_m;
    p.rear_x = rear * size.x / layout.size_m.x;
    poses.push_back(p);
  }
  // The ego car's glass and hull stop spray below when the glass is given; else its box does.
  find_targets(sources, glass && !sources.empty() ? 1 : 0);
  std::vector<std::pair<std::uint32_t, std::size_t>> by_key;
  for (std::size_t i = 0; i < poses.size(); ++i) by_key.emplace_back(poses[i].key, i);
  std::sort(by_key.begin(), by_key.end());
  auto pose_of = [&](std::uint32_t key) -> const Pose* {
    const auto it =
        std::lower_bound(by_key.begin(), by_key.end(), std::make_pair(key, std::size_t{0}));
    return it != by_key.end() && it->first == key ? &poses[it->second] : nullptr;
  };
  const Pose* ego = glass && !poses.empty() ? &poses[0] : nullptr;
  const glm::dmat3 ego_inverse = ego ? glm::transpose(ego->rotation) : glm::dmat3(1.0);
  const glm::dvec3 ego_before = ego ? ego->position - ego->velocity * dt : glm::dvec3(0.0);
  const glm::dvec3 glass_normal = glass ? glass->normal() : glm::dvec3(0.0);

  double ego_caught = 0.0;
  const glm::dvec3 gravity(0.0, 0.0, -kGravity);
  const double eddy_keep = std::exp(-dt / c.eddy_s);
  std::size_t kept = 0;
  for (std::size_t i = 0; i < particles_.size(); ++i) {
    SprayParticle p = particles_[i];
    const int k = static_cast<int>(p.kind);
    const Pose* from = pose_of(p.source);
    glm::dvec3 air = wind;
    double strength = 0.0;
    if (from) air += wake(*from, p.position_m, &strength);
    // The eddy: its variance relaxes to sigma^2 over the eddies' time (uniform kicks, variance
    // 1/3 times 3).
    const double sigma =
        c.turbulence_mps + c.wake_turbulence * strength * (from ? from->speed : 0.0);
    const double kick = sigma * std::sqrt(3.0 * (1.0 - eddy_keep * eddy_keep));
    p.eddy_mps = glm::vec3(glm::dvec3(p.eddy_mps) * eddy_keep +
                           kick * glm::dvec3(random_.uniform(-1.0, 1.0), random_.uniform(-1.0, 1.0),
                                             random_.uniform(-1.0, 1.0)));
    air += glm::dvec3(p.eddy_mps);
    const Drag drag = drag_at(k, glm::length(air - p.velocity_mps));
    const glm::dvec3 settled = air + gravity / drag.rate;
    const glm::dvec3 before = p.position_m;
    p.position_m += settled * dt + (p.velocity_mps - settled) * drag.gone;
    p.velocity_mps = settled + (p.velocity_mps - settled) * drag.decay;
    p.age_s += static_cast<float>(dt);

    bool gone = false;
    if (ego) {
      // In the ego car's frame, which moved by its velocity over the step.
      const glm::dvec3 q0 = ego_inverse * (before - ego_before);
      const glm::dvec3 q1 = ego_inverse * (p.position_m - ego->position);
      if (q1.x > -2.0 && q1.x < 6.0 && std::abs(q1.y) < 2.0 && q1.z < 3.0) {
        const double s0 = glm::dot(q0 - glass->bottom_left_m, glass_normal);
        const double s1 = glm::dot(q1 - glass->bottom_left_m, glass_normal);
        if (s0 > 0.0 && s1 <= 0.0) {
          const glm::dvec3 hit = q0 + (q1 - q0) * (s0 / (s0 - s1)) - glass->bottom_left_m;
          const glm::dvec2 uv(glm::dot(hit, glass->u_axis()) * 1e3,
                              glm::dot(hit, glass->v_axis()) * 1e3);
          if (glass->contains(uv)) {
            gone = true;
            const double caught = p.volume_m3 * c.glass_capture[k];
            ledger_.dispersed_m3 += p.volume_m3 - caught;
            const double mg = caught * 1e9;
            const int drops = std::clamp(static_cast<int>(std::ceil(mg / c.glass_drop_mg)), 1, 16);
            const double spread_mm = radius_m(p) * 1e3 * 0.5;
            for (int d = 0; d < drops; ++d) {
              const glm::dvec2 at = uv + spread_mm * glm::dvec2(random_.uniform(-1.0, 1.0),
                                                                random_.uniform(-1.0, 1.0));
              const bool stayed = glass_hit && glass_hit(at, mg / drops);
              (stayed ? ledger_.on_glass_m3 : ledger_.dispersed_m3) += caught / drops;
            }
          }
        }
        namespace body = car_body;
        const bool in_hull = q1.x > body::kHullRearX && q1.x < body::kHullFrontX &&
                             std::abs(q1.y) < body::kHullHalfWidth && q1.z > 0.2 &&
                             q1.z < body::kHullTopZ;
        // (The cabin's front is the glass, which leans back from kCabinFrontX.)
        const bool in_cabin = q1.x > body::kCabinRearX && s1 <= 0.0 &&
                              std::abs(q1.y) < body::kCabinHalfWidth && q1.z >= body::kHullTopZ &&
                              q1.z < body::kRoofZ;
        if (!gone && p.source != ego->key && (in_hull || in_cabin)) {
          gone = true;
          ledger_.on_body_m3 += p.volume_m3;
          ego_caught += p.volume_m3;
        }
      }
    }
    if (!gone) {
      if (Target* hit = target_at(p.position_m, p.source)) {
        gone = true;
        ledger_.on_body_m3 += p.volume_m3;
        hit->wet_m3 += p.volume_m3;
      }
    }
    const Pose* plane = from ? from : (poses.empty() ? nullptr : &poses[0]);
    if (!gone && plane && p.position_m.z < plane->ground_z(p.position_m)) {
      gone = true;
      const double back =
          p.kind == SprayKind::kLarge ? ground.give(glm::dvec2(p.position_m), p.volume_m3) : 0.0;
      ledger_.returned_m3 += back;
      ledger_.landed_m3 += p.volume_m3 - back;
    }
    if (!gone && p.kind == SprayKind::kMist && p.age_s > c.mist_life_s) {
      gone = true;
      ledger_.dispersed_m3 += p.volume_m3;
    }
    if (!gone &&
        (p.age_s > c.max_life_s ||
         (!poses.empty() && glm::length(p.position_m - poses[0].position) > c.max_range_m))) {
      gone = true;
      ledger_.dropped_m3 += p.volume_m3;
    }
    if (!gone) particles_[kept++] = p;
  }
  particles_.resize(kept);
  if (ego) targets_.push_back({ego->key, {}, 0.0, {}, {}, {}, {}, ego_caught});
  wet_bodies();

  // Vehicles far from the ego car throw nothing (their parcels would be let go by range), nor do
  // those not on their wheels.
  for (const Pose& v : poses) {
    if (glm::length(v.position - poses[0].position) > c.max_range_m) continue;
    if (v.rotation[2].z < 0.5) continue;
    emit(v, ground);
  }
  // Over the budget, the oldest go first (they are at the front).
  if (particles_.size() > c.max_particles) {
    const std::size_t excess = particles_.size() - c.max_particles;
    for (std::size_t i = 0; i < excess; ++i) ledger_.dropped_m3 += particles_[i].volume_m3;
    particles_.erase(particles_.begin(), particles_.begin() + static_cast<std::ptrdiff_t>(excess));
  }
}

void Spray::image(glm::dvec3 origin, SprayImage& out) {
  const SprayConfig& c = config_;
  out.origin_m = origin;
  out.points.clear();
  out.points.reserve(particles_.size());
  out.counts = {};
  for (const SprayParticle& p : particles_) {
    const glm::dvec3 r = p.position_m - origin;
    const int k = static_cast<int>(p.kind);
    const double size = radius_m(p);
    // Droplets of diameter d holding V spread evenly over a sphere of radius R: n = 6V / (pi d^3)
    // / (4/3 pi R^3), extinction n pi d^2 / 2, through the centre (2R): 9 V / (2 pi d R^2).
    const double d = c.diameter_mm[k] * 1e-3;
    const double haze = 9.0 * p.volume_m3 / (2.0 * M_PI * d * size * size);
    const double liquid =
        p.kind == SprayKind::kMist ? 0.0 : std::min(static_cast<double>(p.gathered_m), size);
    out.points.push_back({static_cast<float>(r.x), static_cast<float>(r.y), static_cast<float>(r.z),
                          static_cast<float>(size), static_cast<float>(liquid),
                          static_cast<float>(haze), p.kind, p.splash, false});
    ++out.counts[k];
  }
  classify(out);
}

// Body or spray: neighbours counted in a hash of cells twice as wide as the neighbour radius, so
// that the 8 cells of the 2 x 2 x 2 block nearest a parcel hold every neighbour (27 cells as wide
// as the radius would be three times the look-ups, each a cache miss), liquid parcels only. The
// parcels are sorted by bucket into arrays of their own (position and cell), so that a bucket is
// read in one run; a bucket may hold other cells' parcels (the hash's collisions), which its cell
// tells apart, so that each neighbour is counted once, for its own cell.
void Spray::classify(SprayImage& out) {
  const double h = config_.neighbour_radius_m;
  const float h2 = static_cast<float>(h * h);
  const float inv_side = static_cast<float>(0.5 / h);
  const std::size_t n = out.points.size();
  std::size_t buckets = 64;
  while (buckets < 2 * n) buckets *= 2;
  auto bucket = [&](glm::ivec3 q) {
    const std::uint64_t key = static_cast<std::uint64_t>(q.x) * 73856093u ^
                              static_cast<std::uint64_t>(q.y) * 19349663u ^
                              static_cast<std::uint64_t>(q.z) * 83492791u;
    return static_cast<std::size_t>(key & (buckets - 1));
  };
  // Counting sort of the liquid parcels by bucket.
  Classified& c = classified_;
  c.cell.resize(n);
  c.bucket.resize(n);
  c.start.assign(buckets + 1, 0);
  for (std::size_t i = 0; i < n; ++i) {
    const SprayImage::Point& p = out.points[i];
    if (p.kind == SprayKind::kMist) continue;
    c.cell[i] = glm::ivec3(static_cast<int>(std::floor(p.x * inv_side)),
                           static_cast<int>(std::floor(p.y * inv_side)),
                           static_cast<int>(std::floor(p.z * inv_side)));
    c.bucket[i] = static_cast<std::uint32_t>(bucket(c.cell[i]));
    ++c.start[c.bucket[i] + 1];
  }
  for (std::size_t b = 0; b < buckets; ++b) c.start[b + 1] += c.start[b];
  c.sorted.resize(c.start[buckets]);
  c.fill.assign(c.start.begin(), c.start.end() - 1);
  for (std::size_t i = 0; i < n; ++i) {
    const SprayImage::Point& p = out.points[i];
    if (p.kind != SprayKind::kMist)
      c.sorted[c.fill[c.bucket[i]]++] = {p.x, p.y, p.z, c.cell[i], static_cast<std::uint32_t>(i)};
  }
  // In the sorted order: a cell's parcels one after another look up the same cells.
  const int enough = config_.body_neighbours;
  for (const Classified::Entry& e : c.sorted) {
    SprayImage::Point& p = out.points[e.index];
    const glm::ivec3 q = e.cell;
    // The block's lower corner: towards the nearer neighbour cell on each axis.
    const glm::ivec3 lo(q.x - (p.x * inv_side - static_cast<float>(q.x) < 0.5f ? 1 : 0),
                        q.y - (p.y * inv_side - static_cast<float>(q.y) < 0.5f ? 1 : 0),
                        q.z - (p.z * inv_side - static_cast<float>(q.z) < 0.5f ? 1 : 0));
    int found = -1;  // the parcel itself is among them
    for (int k8 = 0; k8 < 8 && found < enough; ++k8) {
      const glm::ivec3 cell = lo + glm::ivec3(k8 & 1, k8 >> 1 & 1, k8 >> 2);
      const std::size_t b = bucket(cell);
      // (In a dense sheet a cell holds hundreds: enough found, the rest need not be.)
      for (std::uint32_t k = c.start[b]; k < c.start[b + 1] && found < enough; ++k) {
        const Classified::Entry& o = c.sorted[k];
        if (o.cell != cell) continue;
        const float ex = o.x - p.x, ey = o.y - p.y, ez = o.z - p.z;
        found += ex * ex + ey * ey + ez * ez <= h2;
      }
    }
    p.body = found >= enough;
    // A body is a sheet: its parcels overlap, so that its surface is one.
    if (p.body)
      p.liquid_radius_m = std::max(p.liquid_radius_m, static_cast<float>(kSheetRadius * h));
  }
}

}  // namespace downpour::sim
