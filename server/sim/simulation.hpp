// One session's deterministic world: the simulator's inputs and the clock, advanced in fixed
// sub-steps: the windshield's water, the rain in the air and the water on the road.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <unordered_map>
#include <vector>

#include "server/sim/lights.hpp"
#include "server/sim/rain_field.hpp"
#include "server/sim/road_water.hpp"
#include "server/sim/spray.hpp"
#include "server/sim/types.hpp"
#include "server/sim/water.hpp"
#include "server/sim/windshield.hpp"
#include "server/sim/wipers.hpp"

namespace downpour::sim {

class WorkerThread;

// Where the time of the last advance() went (the benchmarks report it; the state never depends on
// it).
struct AdvanceTiming {
  double water_ms = 0.0;    // the windshield water's sub-steps
  double publish_ms = 0.0;  // the state the renderer reads: the glass's water, the road's, spray
  double surface_ms = 0.0;  // of which: the glass water's bodies, their grid and wet fraction
  double spray_image_ms = 0.0;  // and the spray's parcels for the renderer, body or spray
  double rain_ms = 0.0;         // the rain in the air: its steps and its copy for the renderer
  double road_ms = 0.0;         // the water on the road's steps
  double spray_ms = 0.0;        // the spray's steps
  // The glass's water waiting for the world outside it (the spray that lands on the glass), when
  // the outside steps on a helper thread.
  double waited_ms = 0.0;
};

struct SimulationConfig {
  double sub_step_s = 1.0 / 240.0;           // fixed, so that lockstep runs reproduce
  std::shared_ptr<const RoadNetwork> roads;  // null: the built-in track
  EgoGeometry ego;
  WindshieldConfig windshield;
  RainFieldConfig rain;
  RoadWaterConfig road;
  int sub_steps_per_road_step = 8;   // 1/30 s: the road's water changes over seconds
  SprayConfig spray;                 // its step_s is set to sub_steps_per_spray_step sub-steps
  int sub_steps_per_spray_step = 4;  // 1/60 s
  bool simulate_water = true;  // false: the glass stays dry (tools and tests of other effects)
  bool simulate_road = true;   // false: the road stays dry
  bool simulate_spray = true;  // false: no spray
};

// What the renderer reads: a copy, taken on the render thread after a step.
struct SceneState {
  double sim_time_s = 0.0;
  double client_time_s = 0.0;
  std::uint64_t sub_steps = 0;
  VehicleState vehicle;
  WiperState wipers;
  Weather weather;
  std::vector<TrafficVehicle> traffic;
  GlassConfig glass;
  WindshieldState windshield;             // published once per advance(), not per sub-step
  RainState rain;                         // likewise
  std::array<TireWater, kTires> tires{};  // the road's water under the ego car's tires, likewise
  EgoPlace ego_place;                     // likewise
  // The road's water around the car, for drawing; shared by copies, replaced after each road
  // step (null before the first).
  std::shared_ptr<const RoadWaterImage> road_water;
  // The spray's parcels, relative to the ego car's reference point when taken; replaced after each
  // advance() (null before the first); inputs_after() carries the last one.
  std::shared_ptr<const SprayImage> spray;
  // The lamps lit, the automatic ones resolved (sim/lights.hpp): the ego car's, and the traffic's
  // in the order of `traffic`. Flashing lamps are lit at the frame's time (indicator_lit).
  VehicleLights ego_lights;
  std::vector<VehicleLights> traffic_lights;
  // How far each vehicle has rolled at sim_time_s (VehicleMotion): its wheels' turn times their
  // radius. The ego car's, and the traffic's in the order of `traffic`.
  double ego_rolled_m = 0.0;
  std::vector<double> traffic_rolled_m;
  // How wet the spray has made each vehicle's body (0 dry to 1; the weather's rain wets it too,
  // as it does the ground): the ego car's, and the traffic's in the order of `traffic`.
  float ego_body_wet = 0.0f;
  std::vector<float> traffic_body_wet;
  // The roads the session drives on (road_network.hpp): the built-in track's unless the session
  // brought its own.
  std::shared_ptr<const RoadNetwork> roads;
  EgoGeometry ego;
  // The latest picture each client-background view was sent (null: none yet). Not part of the
  // simulation: it only shows behind what the simulation draws.
  ClientImages client_images{};
};

class Simulation {
 public:
  Simulation(std::uint64_t seed, const Update& initial, SimulationConfig config = {});

  void apply(const Update& update);
  // Advances by dt in whole sub-steps; the remainder carries into the next call. With a helper,
  // the world outside the glass (the rain in the air, the road's water, the spray) steps on it
  // beside the windshield's water; the state is the same bit for bit with one or without.
  void advance(double dt_s, WorkerThread* helper = nullptr);
  // The state as advance(dt_s) will leave it but for the windshield (left empty) and the rain (the
  // last step's, whose drops the rain layer moves on to the time after the step): the inputs and
  // the time after the step, for what can be drawn while the step runs.
  SceneState inputs_after(double dt_s) const;

  const SceneState& state() const { return state_; }
  const WaterSim& water() const { return water_; }
  const RainField& rain() const { return rain_; }
  const RoadWater& road() const { return road_; }
  const Spray& spray() const { return spray_; }
  const AdvanceTiming& last_advance_timing() const { return timing_; }
  // The relative air (wind minus the car's velocity) in the vehicle frame, m/s.
  glm::dvec3 air_velocity_vehicle() const;

 private:
  struct LandedDrop;
  void road_and_spray_sub_step(std::uint64_t n, std::vector<LandedDrop>& landed);
  bool start_glass_sub_step();
  void step_glass_water();
  void spray_step(double time_s, std::vector<LandedDrop>& landed);
  void publish();  // all of the below, in turn
  void publish_outside();
  void publish_glass(WorkerThread* helper = nullptr);
  void publish_rest();
  bool whole_sub_step_due(double carry_s) const;

  SimulationConfig config_;
  SceneState state_;
  // Each vehicle's velocity at its last update, for automatic brake lights (traffic by id, those
  // in the last list only).
  VehicleMotion ego_motion_;
  std::unordered_map<std::uint32_t, VehicleMotion> traffic_motion_;
  void resolve_lights(bool vehicle_moved, bool traffic_moved);
  void roll(SceneState& scene) const;        // its *_rolled_m at its sim_time_s
  void wet_bodies(SceneState& scene) const;  // its *_body_wet from the spray
  glm::dvec3 spray_ego_size() const;         // the ego car as a spray source
  std::uint64_t seed_;
  double carry_s_ = 0.0;
  WiperMotion wipers_;
  WaterSim water_;
  RainField rain_;
  std::array<BladePose, 2> blades_at_water_step_;
  int sub_steps_since_water_ = 0;
  // The road's relief from the seed, shared by copies of the simulation (it never changes; the
  // road water refers to it wherever a simulation is moved or copied), and its water.
  std::shared_ptr<const RoadSurface> surface_;
  RoadWater road_;
  int sub_steps_since_road_ = 0;
  bool road_image_stale_ = true;  // a road step since state_.road_water was made
  Spray spray_;
  int sub_steps_since_spray_ = 0;
  // The sim time at the end of the advance under way: the inputs' poses are the vehicles' then,
  // and the spray's sources are moved back along their velocity to each spray step's time.
  double step_end_s_ = 0.0;
  double spray_ms_ = 0.0;
  AdvanceTiming timing_;
  double rain_ms_ = 0.0;             // the rain field's time in this advance, so far
  double road_ms_ = 0.0;             // the road water's, likewise
  double outside_publish_ms_ = 0.0;  // publish_outside()'s road and spray images
  // The spray's drops that stayed on the glass: this advance's by its sub-step (the outside's
  // steps add them, the glass's steps take them in), and those that landed after the glass's last
  // step of an earlier advance.
  struct LandedDrop {
    glm::dvec2 uv_mm;
    double mass_mg;
  };
  std::vector<std::vector<LandedDrop>> landed_;
  std::vector<LandedDrop> pending_;
};

}  // namespace downpour::sim
