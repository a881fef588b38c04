// Water on the windshield (seed 000, section 1): a thin coordinator of the paper's
// parts, each in a file of its own: the mesh model for drops away from the wipers
// (mesh_model.hpp), the particle model around each blade (particle_model.hpp), rain arriving from
// physics (rain_arrival.hpp) and the blades' sweep (blade_sweep.hpp); here, their order within a
// step, the switching of particles back to mesh drops (with the paper's suspension), the ledger of
// where the water went, and the metaballs the renderer draws. Glass space, millimetres; masses
// in milligrams (= cubic millimetres of water). Deterministic: fixed steps and the session's seed.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "server/sim/blade_sweep.hpp"
#include "server/sim/drop_physics.hpp"
#include "server/sim/mesh_model.hpp"
#include "server/sim/particle_model.hpp"
#include "server/sim/rain_arrival.hpp"
#include "server/sim/water_inputs.hpp"
#include "server/sim/windshield.hpp"

namespace downpour::sim {

class WorkerThread;

// Where the water went, mg: arrived = on the glass + wiped_off + drained + evaporated.
struct WaterLedger {
  double arrived = 0.0;     // raindrops that hit the glass (and water placed by tests)
  double wiped_off = 0.0;   // pushed past the glass edge by a blade
  double drained = 0.0;     // ran off the edge by itself
  double evaporated = 0.0;  // trail drops that shrank away
};

class WaterSim {
 public:
  using Drop = MeshModel::Drop;
  using Particle = ParticleModel::Particle;

  WaterSim(const WindshieldConfig& config, std::uint64_t seed);

  void step(double dt_s, const WaterInputs& inputs);
  // With a helper, it shares the surface's index (GlassWaterSurface::index).
  void publish(WindshieldState& out, WorkerThread* helper = nullptr) const;

  WaterLedger ledger() const;
  double mass_on_glass() const;
  std::uint32_t drop_count() const { return mesh_.count(); }
  const std::vector<Drop>& drops() const { return mesh_.drops(); }  // alive: alive = true
  const std::vector<Particle>& particles() const { return particles_.particles(); }
  const WindshieldConfig& config() const { return config_; }

  // Tests and tools: place water directly (counted as arrived). add_drop fuses into an occupied
  // cell; returns false outside the glass.
  bool add_drop(glm::dvec2 pos_mm, double mass_mg, bool with_sub_metaballs = false);
  // Whether add_drop would keep this drop (on the glass, with water in it); any thread may ask.
  bool holds(glm::dvec2 pos_mm, double mass_mg) const {
    return config_.glass.contains(pos_mm) && mass_mg > 0.0;
  }
  void add_particle(glm::dvec2 pos_mm, double mass_mg);
  int drop_at(glm::dvec2 pos_mm) const { return mesh_.drop_at(pos_mm); }  // -1 if none
  double particle_mass() const { return particles_.particle_mass(); }
  // The fixed random affinity of the cell containing pos (glass irregularity).
  double affinity_at(glm::dvec2 pos_mm) const { return mesh_.affinity_at(pos_mm); }
  // Would a drop of this radius flow under these inputs? (gravity + airflow against pinning)
  glm::dvec2 drive_per_pin(double radius_mm, const WaterInputs& inputs) const;

 private:
  // The switching of seed 000 (section 1.3): particles outside every moving blade's region
  // become mesh drops, unless suspended next to a large drop (for at most suspension_max_s).
  void release_particles(double dt, const WaterInputs& in);
  // A surface its last reader has given back, or a new one: publish fills it in place (a tick's
  // surface is a few hundred kilobytes; reused, the step allocates no more than its handle).
  std::shared_ptr<GlassWaterSurface> recycled_surface() const;

  WindshieldConfig config_;
  MeshModel mesh_;
  ParticleModel particles_;
  RainArrival rain_;
  BladeSweep sweep_;
  struct SurfacePool;
  std::shared_ptr<SurfacePool> surfaces_;
  std::array<BladePose, 2> blades_{};  // as of the last step
  double arrived_ = 0.0;
  double released_off_ = 0.0;  // particles left beyond the glass's edge
};

}  // namespace downpour::sim
