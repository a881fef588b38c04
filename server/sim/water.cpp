#include "server/sim/water.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <mutex>

#include <glm/geometric.hpp>

#include "server/sim/glass_water_surface.hpp"

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
      sweep_(config.water, seed),
      surfaces_(std::make_shared<SurfacePool>()) {
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
  if (!holds(pos, mass)) return false;
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
  const ParticleModel::Regions regions = particles_.regions(active);
  std::vector<Particle>& particles = particles_.particles();
  std::size_t kept = 0;
  for (std::size_t i = 0; i < particles.size(); ++i) {
    const Particle p = particles[i];
    if (!config_.glass.contains(p.pos)) {
      released_off_ += p.mass;
      continue;
    }
    if (any && regions.contain(p.pos)) {
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

// Surfaces given back by their last reader (a render thread), under a lock.
struct WaterSim::SurfacePool {
  std::mutex mutex;
  std::vector<std::unique_ptr<GlassWaterSurface>> free;
};

std::shared_ptr<GlassWaterSurface> WaterSim::recycled_surface() const {
  std::unique_ptr<GlassWaterSurface> surface;
  {
    std::lock_guard<std::mutex> lock(surfaces_->mutex);
    if (!surfaces_->free.empty()) {
      surface = std::move(surfaces_->free.back());
      surfaces_->free.pop_back();
    }
  }
  if (!surface) surface = std::make_unique<GlassWaterSurface>();
  surface->bodies.clear();
  // The pool outlives the simulation while a reader still holds one of its surfaces.
  return std::shared_ptr<GlassWaterSurface>(
      surface.release(), [pool = surfaces_](GlassWaterSurface* given_back) {
        std::unique_ptr<GlassWaterSurface> owned(given_back);
        constexpr std::size_t kKept = 4;  // readers hold one for a frame or two
        std::lock_guard<std::mutex> lock(pool->mutex);
        if (pool->free.size() < kKept) pool->free.push_back(std::move(owned));
      });
}

void WaterSim::publish(WindshieldState& out, WorkerThread* helper) const {
  const WaterConfig& w = config_.water;
  const WaterShapeConfig& shape = w.shape;
  out.metaballs.clear();
  out.metaballs.reserve(mesh_.count() * 2 + particles_.particles().size());
  std::shared_ptr<GlassWaterSurface> surface = recycled_surface();
  std::vector<WaterBody>& bodies = surface->bodies;
  bodies.reserve(mesh_.count() * 2 + particles_.particles().size());
  auto add = [&](glm::dvec2 p, double r) {
    out.metaballs.push_back(
        {static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(r)});
  };
  // Every drop meets the glass at the same angle: its trigonometry once.
  const WaterBody unit =
      cap_body({0.0f, 0.0f}, 1.0f, kContactAngleDeg, true, shape.capillary_length_mm);
  auto cap = [&](glm::dvec2 p, double r) {
    WaterBody b = unit;
    b.u_mm = static_cast<float>(p.x);
    b.v_mm = static_cast<float>(p.y);
    b.side_mm = b.front_mm = b.back_mm = static_cast<float>(r);
    return b;
  };
  // Gravity along the glass, in g: what makes a resting drop sag into a tear.
  const double along = std::cos(config_.glass.rake_deg * M_PI / 180.0);
  const double trail_length = std::max(w.trail_spacing_cells, 1) * w.cell_mm;
  // A rivulet's half-width grows with the root of its water per length.
  const double width_per_root_mass = cylinder_half_width_mm(1.0, 1.0, kContactAngleDeg);
  // Life fractions in published_stages steps: trails shrink and sub-metaballs migrate stepwise.
  const double stages = std::max(w.published_stages, 1);
  auto staged = [&](double fraction) { return std::floor(fraction * stages) / stages; };
  for (const Drop& d : mesh_.drops()) {
    if (!d.alive) continue;
    if (d.trail) {
      const double left = 1.0 - staged(d.age / w.trail_lifetime_s);
      add(d.pos, d.trail_radius0 * left);
      // A piece of rivulet as long as the trail's spacing, holding this trail drop's water.
      const double mass = d.trail_mass0 * left * left * left;
      const double half_width = std::sqrt(mass / trail_length) * width_per_root_mass;
      if (half_width > 0.05) {
        WaterBody b = cap(d.pos, half_width);
        b.axis_u = static_cast<float>(d.heading.x);
        b.axis_v = static_cast<float>(d.heading.y);
        b.half_length_mm = static_cast<float>(0.5 * trail_length);
        b.top_mm = 0.0f;  // a thread of water: never flattened
        bodies.push_back(b);
      }
      continue;
    }
    add(d.pos, d.radius);
    WaterBody body = cap(d.pos, d.radius);
    if (d.moving) {
      // Running: a rounded front along the run, a tail behind.
      body.axis_u = static_cast<float>(d.heading.x);
      body.axis_v = static_cast<float>(d.heading.y);
      body.back_mm = static_cast<float>(shape.run_back * d.radius);
      body.side_mm = static_cast<float>(shape.run_side * d.radius);
      add(d.pos - 0.9 * d.radius * d.heading, 0.7 * d.radius);
    } else {
      // Resting: sagging downhill by its Bond number along the glass.
      const double ratio = d.radius / shape.capillary_length_mm;
      const double bond = std::min(ratio * ratio * along, 1.0);
      body.front_mm = static_cast<float>(d.radius * (1.0 + shape.tear_front * bond));
      body.back_mm = static_cast<float>(d.radius * (1.0 - shape.tear_back * bond));
    }
    bodies.push_back(body);
    if (d.subs > 0) {
      // Impact sub-metaballs migrate into the main one as they age.
      const double offset =
          (1.0 - staged(d.sub_age / w.sub_metaball_merge_s)) * w.sub_metaball_offset * d.radius;
      for (int k = 0; k < d.subs; ++k) {
        const glm::dvec2 at = d.pos + offset * glm::dvec2(d.sub_dir[k]);
        add(at, w.sub_metaball_radius * d.radius);
        bodies.push_back(cap(at, w.sub_metaball_radius * d.radius));
      }
    }
  }
  // (A particle's radius once; that of the mass particles are made with, once for them all.)
  const double one_mass = particles_.particle_mass(), one_radius = drop_radius_mm(one_mass);
  for (const Particle& p : particles_.particles()) {
    const double r = p.mass == one_mass ? one_radius : drop_radius_mm(p.mass);
    add(p.pos, r);
    bodies.push_back(cap(p.pos, r));
  }
  surface->index(config_.glass, helper);
  out.glass_wet_fraction = surface->wet_fraction;
  out.surface = std::move(surface);
  out.blades = blades_;
  out.drops = mesh_.count();
  out.particles = static_cast<std::uint32_t>(particles_.particles().size());
}

}  // namespace downpour::sim
