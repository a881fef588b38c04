#include "server/sim/water.hpp"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

namespace downpour::sim {
namespace {

// Airflow along the glass (u, v), m/s: the relative air's component in the glass plane, slowed
// to what reaches the drops in the boundary layer.
glm::dvec2 airflow_on_glass(const WindshieldConfig& c, const WaterInputs& in) {
  const glm::dvec3 a = in.air_velocity_mps;
  return c.water.airflow_fraction *
         glm::dvec2(glm::dot(a, c.glass.u_axis()), glm::dot(a, c.glass.v_axis()));
}

}  // namespace

WaterSim::WaterSim(const WindshieldConfig& config, std::uint64_t seed)
    : config_(config),
      mesh_(config, seed),
      particles_(config.water),
      rain_(config, seed),
      sweep_(config.water, seed) {
  for (int b = 0; b < 2; ++b) {  // parked until the first step says otherwise
    const BladeConfig& c = config_.wipers.blades[b];
    blades_[b] = {glm::vec2(c.pivot_mm), static_cast<float>(c.park_deg * M_PI / 180.0),
                  static_cast<float>(c.length_mm), static_cast<float>(c.width_mm)};
  }
}

void WaterSim::step(double dt, const WaterInputs& in) {
  blades_ = in.blades_after;
  rain_.step(dt, in, [this](glm::dvec2 pos, double mass) {
    arrived_ += mass;
    mesh_.place(pos, mass, &rain_.random());
  });
  mesh_.step(dt, airflow_on_glass(config_, in));
  sweep_.sweep(in, mesh_, particles_);
  particles_.repel();
  release_particles(dt, in);
}

WaterLedger WaterSim::ledger() const {
  return {arrived_, sweep_.wiped_off() + released_off_, mesh_.drained(), mesh_.evaporated()};
}

double WaterSim::mass_on_glass() const {
  return mesh_.mass() + particles_.mass() + sweep_.carried();
}

bool WaterSim::add_drop(glm::dvec2 pos, double mass, bool with_sub_metaballs) {
  if (!config_.glass.contains(pos) || mass <= 0.0) return false;
  arrived_ += mass;
  mesh_.place(pos, mass, with_sub_metaballs ? &rain_.random() : nullptr);
  return true;
}

void WaterSim::add_particle(glm::dvec2 pos, double mass) {
  arrived_ += mass;
  particles_.add(pos, mass);
}

glm::dvec2 WaterSim::drive_per_pin(double r, const WaterInputs& in) const {
  return mesh_.drive_per_pin(r, airflow_on_glass(config_, in));
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
  std::vector<Particle>& particles = particles_.particles();
  std::size_t kept = 0;
  for (std::size_t i = 0; i < particles.size(); ++i) {
    const Particle p = particles[i];
    if (!config_.glass.contains(p.pos)) {
      released_off_ += p.mass;
      continue;
    }
    if (any && particles_.in_region(p.pos, active)) {
      particles[kept++] = {p.pos, p.mass, 0.0};
      continue;
    }
    if (p.held_s < config_.water.suspension_max_s && mesh_.holds_critical_drop_near(p.pos)) {
      particles[kept++] = {p.pos, p.mass, p.held_s + dt};
      continue;
    }
    mesh_.place(p.pos, p.mass, nullptr);
  }
  particles.resize(kept);
}

void WaterSim::publish(WindshieldState& out) const {
  const WaterConfig& w = config_.water;
  out.metaballs.clear();
  out.metaballs.reserve(mesh_.count() * 2 + particles_.particles().size());
  auto add = [&](glm::dvec2 p, double r) {
    out.metaballs.push_back(
        {static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(r)});
  };
  // Life fractions in published_stages steps: trails shrink and sub-metaballs migrate stepwise.
  const double stages = std::max(w.published_stages, 1);
  auto staged = [&](double fraction) { return std::floor(fraction * stages) / stages; };
  for (const Drop& d : mesh_.drops()) {
    if (!d.alive) continue;
    add(d.pos, d.trail ? d.trail_radius0 * (1.0 - staged(d.age / w.trail_lifetime_s)) : d.radius);
    if (d.subs > 0) {
      // Impact sub-metaballs migrate into the main one as they age.
      const double offset =
          (1.0 - staged(d.sub_age / w.sub_metaball_merge_s)) * w.sub_metaball_offset * d.radius;
      for (int k = 0; k < d.subs; ++k)
        add(d.pos + offset * glm::dvec2(d.sub_dir[k]), w.sub_metaball_radius * d.radius);
    }
    if (d.moving) add(d.pos - 0.9 * d.radius * d.heading, 0.7 * d.radius);  // a running drop's tail
  }
  for (const Particle& p : particles_.particles()) add(p.pos, drop_radius_mm(p.mass));
  out.blades = blades_;
  out.drops = mesh_.count();
  out.particles = static_cast<std::uint32_t>(particles_.particles().size());
}

}  // namespace downpour::sim
