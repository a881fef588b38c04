#include "server/sim/rain_field.hpp"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

#include "server/sim/car_body.hpp"

namespace downpour::sim {

double marshall_palmer_slope_per_mm(double rain_mm_h) {
  return 4.1 * std::pow(std::max(rain_mm_h, 1e-6), -0.21);
}

double marshall_palmer_density(double rain_mm_h, double d_min_mm) {
  if (!(rain_mm_h > 0.0)) return 0.0;
  const double slope = marshall_palmer_slope_per_mm(rain_mm_h);
  return kMarshallPalmerN0 / slope * std::exp(-slope * d_min_mm);  // integral of N(D) from d_min
}

double rain_extinction_per_m(double rain_mm_h) {
  if (!(rain_mm_h > 0.0)) return 0.0;
  const double slope = marshall_palmer_slope_per_mm(rain_mm_h);
  return M_PI * kMarshallPalmerN0 * 1e-6 / (slope * slope * slope);
}

double visibility_m(double extinction_per_m) {
  return extinction_per_m > 0.0 ? 3.912 / extinction_per_m : 1e9;
}

double marshall_palmer_flux(double rain_mm_h, double d_min_mm, double d_max_mm) {
  if (!(rain_mm_h > 0.0) || !(d_max_mm > d_min_mm)) return 0.0;
  const double slope = marshall_palmer_slope_per_mm(rain_mm_h);
  // Simpson's rule over the sizes; the tail above d_max_mm falls at d_max_mm's speed.
  constexpr int kSteps = 200;
  const double h = (d_max_mm - d_min_mm) / kSteps;
  double sum = 0.0;
  for (int i = 0; i <= kSteps; ++i) {
    const double d = d_min_mm + i * h;
    const double w = i == 0 || i == kSteps ? 1.0 : i % 2 == 1 ? 4.0 : 2.0;
    sum += w * std::exp(-slope * d) * terminal_speed_mps(d);
  }
  const double inside = sum * h / 3.0;
  const double tail = std::exp(-slope * d_max_mm) / slope * terminal_speed_mps(d_max_mm);
  return kMarshallPalmerN0 * (inside + tail);
}

double RainFieldConfig::drawn_min_diameter_mm(double rain_mm_h) const {
  if (!(rain_mm_h > 0.0) || rain_mm_h >= full_tail_mm_h) return min_diameter_mm;
  return std::max(smallest_drawn_mm, min_diameter_mm *
                                         marshall_palmer_slope_per_mm(full_tail_mm_h) /
                                         marshall_palmer_slope_per_mm(rain_mm_h));
}

RainField::RainField(std::uint64_t seed, RainFieldConfig config)
    : config_(config), random_(seed, 4) {}

std::uint32_t RainField::target_count(const Weather& weather) const {
  if (!(weather.rain_rate_mm_h > 0.0)) return 0;
  if (weather.rain_streak_count > 0) return std::min(weather.rain_streak_count, kMaxRainDrops);
  const double n = config_.volume_m3() *
                   marshall_palmer_density(weather.rain_rate_mm_h,
                                           config_.drawn_min_diameter_mm(weather.rain_rate_mm_h));
  return static_cast<std::uint32_t>(std::min<double>(std::lround(n), kMaxRainDrops));
}

glm::dvec3 RainField::fall_direction(const Weather& weather, const VehicleState& vehicle) {
  const double yaw = vehicle.rotation.yaw_deg * M_PI / 180.0;
  const double angle = std::clamp(weather.rain_angle_deg, -70.0, 70.0) * M_PI / 180.0;
  const glm::dvec3 left(-std::sin(yaw), std::cos(yaw), 0.0);
  // Positive angles lean the fall towards the car's left: on screen, the streaks lean left.
  return glm::normalize(left * std::sin(angle) + glm::dvec3(0.0, 0.0, -std::cos(angle)));
}

RainField::Box RainField::box_for(const VehicleState& vehicle) const {
  const double yaw = vehicle.rotation.yaw_deg * M_PI / 180.0;
  Box box;
  box.forward = glm::dvec3(std::cos(yaw), std::sin(yaw), 0.0);
  box.left = glm::dvec3(-std::sin(yaw), std::cos(yaw), 0.0);
  box.ground_z = vehicle.position_m.z;
  const glm::dvec3 eye = vehicle.position_m + box.forward * config_.eye_forward_m;
  box.centre = eye + box.forward * (0.5 * config_.length_m - config_.behind_m);
  box.centre.z = box.ground_z + 0.5 * config_.height_m;
  return box;
}

RainDrop RainField::born(const Box& box, double rain_mm_h, bool anywhere_in_height) {
  RainDrop d;
  // A size from the Marshall-Palmer distribution above the smallest drawn, by inversion. Drops
  // anywhere in the box are the distribution itself; drops entering at its top are the flux
  // through it, N(D) v(D), since faster ones cross the box sooner and are replaced more often:
  // drawn from N(D) and kept in proportion to their speed, so that the box keeps N(D).
  const double slope = marshall_palmer_slope_per_mm(rain_mm_h);
  const double fastest = terminal_speed_mps(config_.max_diameter_mm);
  const double smallest = config_.drawn_min_diameter_mm(rain_mm_h);
  for (;;) {
    const double u = random_.uniform();
    d.diameter_mm = std::min(config_.max_diameter_mm, smallest - std::log1p(-u) / slope);
    d.speed_mps = terminal_speed_mps(d.diameter_mm);
    if (anywhere_in_height || random_.uniform() * fastest <= d.speed_mps) break;
  }
  const double along = random_.uniform(-0.5, 0.5) * config_.length_m;
  const double across = random_.uniform(-0.5, 0.5) * config_.width_m;
  const double up =
      anywhere_in_height ? random_.uniform(-0.5, 0.5) * config_.height_m : 0.5 * config_.height_m;
  d.position_m = box.centre + box.forward * along + box.left * across + glm::dvec3(0.0, 0.0, up);
  return d;
}

void RainField::advance(double dt_s, double time_s, const Weather& weather,
                        const VehicleState& vehicle) {
  weather_ = weather;
  vehicle_ = vehicle;
  carry_s_ += dt_s;
  while (carry_s_ >= config_.step_s * (1.0 - 1e-9)) {
    carry_s_ -= config_.step_s;
    step(config_.step_s, time_s - carry_s_, weather, vehicle);
  }
  time_s_ = time_s - carry_s_;
}

void RainField::splash(const RainSplash& s) {
  (s.on_car ? car_splashes_ : road_splashes_) += 1;
  if (splashes_.size() < kMaxRainSplashes) {
    splashes_.push_back(s);
    return;
  }
  splashes_[next_splash_] = s;  // the oldest goes
  next_splash_ = (next_splash_ + 1) % kMaxRainSplashes;
}

bool RainField::hit_car(const glm::dvec3& before, const glm::dvec3& after, double dt_s,
                        double end_s, double diameter_mm, const VehicleState& vehicle,
                        const Box& box) {
  namespace body = car_body;
  // The box's axes are the car's (its heading, level).
  auto local = [&](const glm::dvec3& p) {
    const glm::dvec3 r = p - vehicle.position_m;
    return glm::dvec3(glm::dot(r, box.forward), glm::dot(r, box.left), r.z);
  };
  const glm::dvec3 a = local(after);
  if (a.z >= body::kRoofZ || a.x < body::kHullRearX || a.x > body::kHullFrontX ||
      std::abs(a.y) > body::kHullHalfWidth) {
    return false;
  }
  const bool in_hull = a.z < body::kHullTopZ;
  const bool in_cabin =
      a.x > body::kCabinRearX && a.x < body::kCabinFrontX && std::abs(a.y) < body::kCabinHalfWidth;
  if (!in_hull && !in_cabin) return false;
  // Where it was at the step's start, relative to the car where it was then.
  const glm::dvec3 b = local(before + vehicle.velocity_mps * dt_s);
  auto land = [&](double surface_z) {
    const double f = std::clamp((b.z - surface_z) / std::max(b.z - a.z, 1e-9), 0.0, 1.0);
    RainSplash s;
    s.position_m = b + (a - b) * f;
    s.position_m.z = surface_z;
    s.time_s = end_s - dt_s * (1.0 - f);
    s.diameter_mm = static_cast<float>(diameter_mm);
    s.on_car = true;
    splash(s);
  };
  const bool under_roof =
      a.x > body::kRoofRearX && a.x < body::kRoofFrontX && std::abs(a.y) < body::kRoofHalfWidth;
  // Where it crossed a surface's height, if the surface is there: a drop that came in from the
  // side (the car drove into it) or through the glass leaves no splash.
  auto crossing = [&](double surface_z) {
    const double f = std::clamp((b.z - surface_z) / std::max(b.z - a.z, 1e-9), 0.0, 1.0);
    return b + (a - b) * f;
  };
  auto on_roof = [&](const glm::dvec3& p) {
    return p.x > body::kRoofRearX && p.x < body::kRoofFrontX &&
           std::abs(p.y) < body::kRoofHalfWidth;
  };
  auto on_hull_top = [&](const glm::dvec3& p) {
    return p.x > body::kHullRearX && p.x < body::kHullFrontX &&
           std::abs(p.y) < body::kHullHalfWidth &&
           !(p.x > body::kCabinRearX && p.x < body::kCabinFrontX &&
             std::abs(p.y) < body::kCabinHalfWidth);
  };
  if (in_cabin && under_roof && b.z >= body::kRoofZ && on_roof(crossing(body::kRoofZ))) {
    land(body::kRoofZ);
  } else if (in_hull && !in_cabin && b.z >= body::kHullTopZ &&
             on_hull_top(crossing(body::kHullTopZ))) {
    land(body::kHullTopZ);  // the bonnet or the boot
  }
  // Otherwise it met the glass (the windshield's own simulation has its rain) or a side.
  return true;
}

void RainField::step(double dt_s, double end_s, const Weather& weather,
                     const VehicleState& vehicle) {
  const Box box = box_for(vehicle);
  const std::uint32_t target = target_count(weather);
  // Fewer: the last ones go. More: new ones anywhere in the box, not a wave from the top.
  if (drops_.size() > target) drops_.resize(target);
  while (drops_.size() < target) drops_.push_back(born(box, weather.rain_rate_mm_h, true));
  if (drops_.empty()) return;

  const glm::dvec3 fall = fall_direction(weather, vehicle);
  const glm::dvec3 wind = wind_velocity(weather);
  const double half_length = 0.5 * config_.length_m, half_width = 0.5 * config_.width_m;
  namespace body = car_body;
  const glm::dvec3 car_middle =
      vehicle.position_m + box.forward * (0.5 * (body::kHullFrontX + body::kHullRearX));
  // The hull's half diagonal, with a margin: where a drop must be, after its move, to be in it.
  const double car_reach =
      std::hypot(0.5 * (body::kHullFrontX - body::kHullRearX), body::kHullHalfWidth) + 0.5;
  const double car_reach_sq = car_reach * car_reach;
  for (RainDrop& d : drops_) {
    const glm::dvec3 before = d.position_m;
    d.position_m += (fall * d.speed_mps + wind) * dt_s;
    if (d.position_m.z < box.ground_z) {
      // Landed on the road: a splash where and when it crossed the ground.
      const double f = std::clamp(
          (before.z - box.ground_z) / std::max(before.z - d.position_m.z, 1e-9), 0.0, 1.0);
      RainSplash s;
      s.position_m = before + (d.position_m - before) * f;
      s.position_m.z = box.ground_z;
      s.time_s = end_s - dt_s * (1.0 - f);
      s.diameter_mm = static_cast<float>(d.diameter_mm);
      splash(s);
      d = born(box, weather.rain_rate_mm_h, false);  // restarts at the top, somewhere new
      continue;
    }
    // Only a drop low enough and within the car's reach (a circle around its middle) can hit it.
    const double dx = d.position_m.x - car_middle.x, dy = d.position_m.y - car_middle.y;
    if (d.position_m.z < box.ground_z + car_body::kRoofZ && dx * dx + dy * dy < car_reach_sq &&
        hit_car(before, d.position_m, dt_s, end_s, d.diameter_mm, vehicle, box)) {
      d = born(box, weather.rain_rate_mm_h, false);
      continue;
    }
    // Out of the box's sides (the car moved on or turned, or the wind carried it): in again from
    // the other side, at the same height.
    const glm::dvec3 rel = d.position_m - box.centre;
    double along = glm::dot(rel, box.forward), across = glm::dot(rel, box.left);
    bool moved = false;
    if (along < -half_length || along > half_length) {
      along -= config_.length_m * std::floor((along + half_length) / config_.length_m);
      moved = true;
    }
    if (across < -half_width || across > half_width) {
      across -= config_.width_m * std::floor((across + half_width) / config_.width_m);
      moved = true;
    }
    if (d.position_m.z > box.ground_z + config_.height_m) {
      d.position_m.z = box.ground_z + config_.height_m;  // the road rose under the box
    }
    if (moved) {
      d.position_m = box.centre + box.forward * along + box.left * across +
                     glm::dvec3(0.0, 0.0, d.position_m.z - box.centre.z);
    }
  }
}

void RainField::publish(RainState* out) const {
  out->time_s = time_s_;
  const Box box = box_for(vehicle_);
  out->origin_m = box.centre;
  out->box_forward = glm::vec3(box.forward);
  out->box_left = glm::vec3(box.left);
  out->box_half_m =
      glm::vec3(0.5 * config_.length_m, 0.5 * config_.width_m, 0.5 * config_.height_m);
  out->fall_direction = glm::vec3(fall_direction(weather_, vehicle_));
  out->wind_mps = glm::vec3(wind_velocity(weather_));
  out->drops.resize(drops_.size());
  for (std::size_t i = 0; i < drops_.size(); ++i) {
    const RainDrop& d = drops_[i];
    out->drops[i] =
        glm::vec4(glm::vec3(d.position_m - out->origin_m), static_cast<float>(d.diameter_mm));
  }
  out->splashes.clear();
  for (const RainSplash& s : splashes_) {
    const double age = time_s_ - s.time_s;
    if (age < 0.0 || age > kSplashLifeS) continue;
    SplashState v;
    v.position = glm::vec3(s.on_car ? s.position_m : s.position_m - out->origin_m);
    v.age_s = static_cast<float>(age);
    v.diameter_mm = s.diameter_mm;
    v.on_car = s.on_car;
    out->splashes.push_back(v);
  }
  out->extinction_per_m = rain_extinction_per_m(weather_.rain_rate_mm_h);
}

}  // namespace downpour::sim
