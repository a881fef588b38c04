#include "server/sim/simulation.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>

#include <glm/mat3x3.hpp>

#include "server/sim/car_body.hpp"
#include "server/sim/pose.hpp"
#include "server/sim/worker_thread.hpp"

namespace downpour::sim {
namespace {

constexpr double kMaxExtrapolationS = 0.5;  // a source is moved along its path at most this

SimulationConfig with_spray_step(SimulationConfig config) {
  config.spray.step_s = config.sub_steps_per_spray_step * config.sub_step_s;
  return config;
}

}  // namespace

Simulation::Simulation(std::uint64_t seed, const Update& initial, SimulationConfig config)
    : config_(with_spray_step(config)),
      seed_(seed),
      wipers_(config.windshield.wipers),
      water_(config.windshield, seed),
      rain_(seed, config.rain),
      blades_at_water_step_(wipers_.poses()),
      surface_(std::make_shared<const RoadSurface>(config.roads ? config.roads : built_in_roads(),
                                                   seed)),
      road_(*surface_, config.road),
      spray_(seed, config_.spray) {
  state_.glass = config_.windshield.glass;
  state_.roads = surface_->roads_shared();
  state_.ego = config_.ego;
  apply(initial);
  publish();
}

void Simulation::publish() {
  publish_outside();
  publish_glass();
  publish_rest();
}

// The images of the world outside the glass: the rain in the air, the road's water, the spray.
void Simulation::publish_outside() {
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  rain_.publish(&state_.rain);
  const auto t1 = Clock::now();
  rain_ms_ += std::chrono::duration<double, std::milli>(t1 - t0).count();
  if (road_image_stale_ || !state_.road_water) {
    auto image = std::make_shared<RoadWaterImage>();
    road_.image(*image);
    state_.road_water = std::move(image);
    road_image_stale_ = false;
  }
  const auto t_spray = Clock::now();
  auto spray = std::make_shared<SprayImage>();
  spray_.image(state_.vehicle.position_m, *spray);
  state_.spray = std::move(spray);
  const auto t2 = Clock::now();
  timing_.spray_image_ms = std::chrono::duration<double, std::milli>(t2 - t_spray).count();
  outside_publish_ms_ = std::chrono::duration<double, std::milli>(t2 - t1).count();
}

void Simulation::publish_glass(WorkerThread* helper) {
  const auto t0 = std::chrono::steady_clock::now();
  water_.publish(state_.windshield, helper);
  timing_.surface_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// What follows from the steps of both: the water under the tires, where the car is, its wheels'
// turn and the bodies' wetness.
void Simulation::publish_rest() {
  // Under each tire: front left, front right, rear left, rear right.
  const glm::dmat4 to_world = vehicle_to_world(state_.vehicle);
  for (int t = 0; t < kTires; ++t) {
    const double half_track = 0.5 * config_.ego.track_m;
    const glm::dvec4 local(t < 2 ? config_.ego.wheelbase_m : 0.0,
                           t % 2 == 0 ? half_track : -half_track, 0.0, 1.0);
    const glm::dvec2 xy(to_world * local);
    const double water = road_.water_m(xy);
    state_.tires[t] = {water * 1e3, road_.standing_m(xy) * 1e3, road_.state_of(water)};
  }
  state_.ego_place = ego_place(surface_->roads(), glm::dvec2(state_.vehicle.position_m));
  roll(state_);
  wet_bodies(state_);
}

// The spray's keys: the ego car's 0, each traffic vehicle's its id + 1 (spray_step()).
void Simulation::wet_bodies(SceneState& scene) const {
  scene.ego_body_wet = static_cast<float>(spray_.body_wetness(0, spray_ego_size()));
  scene.traffic_body_wet.resize(scene.traffic.size());
  for (std::size_t i = 0; i < scene.traffic.size(); ++i) {
    const TrafficVehicle& other = scene.traffic[i];
    scene.traffic_body_wet[i] = static_cast<float>(
        spray_.body_wetness(other.id == UINT32_MAX ? other.id : other.id + 1, other.size_m));
  }
}

void Simulation::roll(SceneState& scene) const {
  scene.ego_rolled_m = ego_motion_.rolled_at(scene.sim_time_s);
  scene.traffic_rolled_m.resize(scene.traffic.size());
  for (std::size_t i = 0; i < scene.traffic.size(); ++i) {
    const auto it = traffic_motion_.find(scene.traffic[i].id);
    scene.traffic_rolled_m[i] =
        it != traffic_motion_.end() ? it->second.rolled_at(scene.sim_time_s) : 0.0;
  }
}

void Simulation::apply(const Update& update) {
  state_.client_time_s = update.client_time_s;
  if (update.vehicle) state_.vehicle = *update.vehicle;
  if (update.wipers) state_.wipers = *update.wipers;
  if (update.weather) state_.weather = *update.weather;
  if (update.traffic) state_.traffic = *update.traffic;
  for (int v = 0; v < kViewCount; ++v) {
    if (update.client_images[v]) state_.client_images[v] = update.client_images[v];
  }
  resolve_lights(update.vehicle.has_value(), update.traffic.has_value());
}

void Simulation::resolve_lights(bool vehicle_moved, bool traffic_moved) {
  if (vehicle_moved) ego_motion_.observe(state_.vehicle, state_.sim_time_s);
  state_.ego_lights =
      sim::resolve_lights(state_.vehicle.lights, state_.weather, ego_motion_.braking);
  if (traffic_moved) {
    std::unordered_map<std::uint32_t, VehicleMotion> seen;
    for (const TrafficVehicle& t : state_.traffic) {
      auto it = traffic_motion_.find(t.id);
      VehicleMotion m = it != traffic_motion_.end() ? it->second : VehicleMotion{};
      m.observe(t.state, state_.sim_time_s);
      seen[t.id] = m;
    }
    traffic_motion_ = std::move(seen);
  }
  state_.traffic_lights.clear();
  for (const TrafficVehicle& t : state_.traffic) {
    const auto it = traffic_motion_.find(t.id);
    state_.traffic_lights.push_back(sim::resolve_lights(
        t.state.lights, state_.weather, it != traffic_motion_.end() && it->second.braking));
  }
}

void Simulation::advance(double dt_s, WorkerThread* helper) {
  using Clock = std::chrono::steady_clock;
  rain_ms_ = 0.0;
  road_ms_ = 0.0;
  spray_ms_ = 0.0;
  carry_s_ += dt_s;
  // The inputs are where the vehicles are at the end of this advance (as the frame draws them).
  const std::uint64_t first = state_.sub_steps;
  int due = 0;
  step_end_s_ = state_.sim_time_s;
  for (; whole_sub_step_due(carry_s_); carry_s_ -= config_.sub_step_s) {
    step_end_s_ += config_.sub_step_s;
    ++due;
  }
  // The world outside the glass steps all of the advance's sub-steps on the helper (or first,
  // without one) while the glass's water follows it. The spray's drops that land on the glass join
  // its water at its first step after the sub-step they landed in (one water step later at most),
  // so the glass never waits for the spray of the sub-step it steps in. Apart from those drops,
  // handed over through `outside_done`, neither side reads what the other writes, so the state is
  // the same bit for bit with a helper or without.
  if (landed_.size() < static_cast<std::size_t>(due)) landed_.resize(due);
  for (int k = 0; k < due; ++k) landed_[k].clear();  // (the outer vector stays as it is now)
  std::atomic<int> outside_done{0};                  // sub-steps whose spray the outside has thrown
  constexpr int kOutsideFailed = std::numeric_limits<int>::max();
  std::exception_ptr outside_failure;
  auto outside = [&] {
    try {
      for (int k = 1; k <= due; ++k) {
        road_and_spray_sub_step(first + static_cast<std::uint64_t>(k), landed_[k - 1]);
        outside_done.store(k, std::memory_order_release);
        outside_done.notify_one();
      }
      // The rain in the air meets nothing else in the step: it goes last.
      const auto r0 = Clock::now();
      for (int k = 1; k <= due; ++k) {
        const double time_s =
            static_cast<double>(first + static_cast<std::uint64_t>(k)) * config_.sub_step_s;
        rain_.advance(config_.sub_step_s, time_s, state_.weather, state_.vehicle);
      }
      rain_ms_ += std::chrono::duration<double, std::milli>(Clock::now() - r0).count();
      publish_outside();
    } catch (...) {
      outside_failure = std::current_exception();
      outside_done.store(kOutsideFailed, std::memory_order_release);
      outside_done.notify_one();
    }
  };
  double waited_ms = 0.0;
  {
    const WaitOnExit joined(helper);  // the helper finishes before what it uses goes
    if (helper) {
      helper->start(outside);
    } else {
      outside();
    }
    const auto g0 = Clock::now();
    auto take = [this](const std::vector<LandedDrop>& drops) {
      for (const LandedDrop& d : drops) water_.add_drop(d.uv_mm, d.mass_mg, true);
    };
    int taken = 0;  // the sub-steps of this advance whose drops the glass has taken
    for (int k = 1; k <= due; ++k) {
      if (!start_glass_sub_step()) continue;
      int seen = outside_done.load(std::memory_order_acquire);
      if (seen < k - 1) {
        const auto w0 = Clock::now();
        while (seen < k - 1) {
          outside_done.wait(seen, std::memory_order_acquire);
          seen = outside_done.load(std::memory_order_acquire);
        }
        waited_ms += std::chrono::duration<double, std::milli>(Clock::now() - w0).count();
      }
      if (seen == kOutsideFailed) break;
      take(pending_);
      pending_.clear();
      for (; taken < k - 1; ++taken) take(landed_[taken]);
      step_glass_water();
    }
    const auto t1 = Clock::now();
    timing_.water_ms = std::chrono::duration<double, std::milli>(t1 - g0).count() - waited_ms;
    publish_glass(helper);  // the helper, if done with the outside, shares the surface's index
    const auto w0 = Clock::now();
    if (helper) helper->wait();
    waited_ms += std::chrono::duration<double, std::milli>(Clock::now() - w0).count();
    // What landed since the glass's last step waits for its next one.
    if (!outside_failure) {
      for (; taken < due; ++taken)
        pending_.insert(pending_.end(), landed_[taken].begin(), landed_[taken].end());
    }
  }
  if (outside_failure) std::rethrow_exception(outside_failure);
  const auto t2 = Clock::now();
  publish_rest();
  const double rest_ms = std::chrono::duration<double, std::milli>(Clock::now() - t2).count();
  timing_.rain_ms = rain_ms_;
  timing_.road_ms = road_ms_;
  timing_.spray_ms = spray_ms_;
  timing_.publish_ms = timing_.surface_ms + outside_publish_ms_ + rest_ms;
  timing_.waited_ms = waited_ms;
}

bool Simulation::whole_sub_step_due(double carry_s) const {
  // A small tolerance keeps dt = k * sub_step from losing a step to rounding.
  return carry_s >= config_.sub_step_s * (1.0 - 1e-9);
}

// (The spray's car is 4.5 m of the 4.6: its hull, bumpers aside.)
glm::dvec3 Simulation::spray_ego_size() const {
  return config_.ego.size_m * glm::dvec3(4.5 / 4.6, 1.0, 1.0);
}

SceneState Simulation::inputs_after(double dt_s) const {
  SceneState inputs;
  inputs.client_time_s = state_.client_time_s;
  inputs.vehicle = state_.vehicle;
  inputs.wipers = state_.wipers;
  inputs.weather = state_.weather;
  inputs.traffic = state_.traffic;
  inputs.ego_lights = state_.ego_lights;
  inputs.traffic_lights = state_.traffic_lights;
  inputs.glass = state_.glass;
  inputs.roads = state_.roads;
  inputs.ego = state_.ego;
  inputs.client_images = state_.client_images;  // the pictures the views draw over
  // The road's water as the last step left it (it changes over seconds; the step may be running
  // while the road is drawn).
  inputs.road_water = state_.road_water;
  // The spray as the last step left it, likewise: its parcels are placed in the world, and a frame
  // old they still are where they were (the views need not wait for the step).
  inputs.spray = state_.spray;
  // The rain as the last step left it: the views draw its drops moved on to the frame's time
  // (RainLayerInputs::dt_s), so that no pass waits for the step for them.
  inputs.rain = state_.rain;
  inputs.sub_steps = state_.sub_steps;
  for (double carry = carry_s_ + dt_s; whole_sub_step_due(carry); carry -= config_.sub_step_s)
    ++inputs.sub_steps;
  inputs.sim_time_s = static_cast<double>(inputs.sub_steps) * config_.sub_step_s;
  roll(inputs);
  wet_bodies(inputs);
  return inputs;
}

glm::dvec3 Simulation::air_velocity_vehicle() const {
  const glm::dmat3 to_world = rotation_matrix(state_.vehicle.rotation);
  return glm::transpose(to_world) * (wind_velocity(state_.weather) - state_.vehicle.velocity_mps);
}

// The road's water and the spray at sub-step `n` of the session (`k` of the advance), at its time.
void Simulation::road_and_spray_sub_step(std::uint64_t n, std::vector<LandedDrop>& landed) {
  using Clock = std::chrono::steady_clock;
  const double time_s = static_cast<double>(n) * config_.sub_step_s;
  if (config_.simulate_road && ++sub_steps_since_road_ >= config_.sub_steps_per_road_step) {
    const auto r0 = Clock::now();
    road_.step(glm::dvec2(state_.vehicle.position_m), state_.weather.rain_rate_mm_h,
               sub_steps_since_road_ * config_.sub_step_s);
    sub_steps_since_road_ = 0;
    road_image_stale_ = true;
    road_ms_ += std::chrono::duration<double, std::milli>(Clock::now() - r0).count();
  }
  if (config_.simulate_spray && ++sub_steps_since_spray_ >= config_.sub_steps_per_spray_step) {
    const auto s0 = Clock::now();
    spray_step(time_s, landed);
    sub_steps_since_spray_ = 0;
    spray_ms_ += std::chrono::duration<double, std::milli>(Clock::now() - s0).count();
  }
}

// The clock and the wipers one sub-step on; whether the windshield's water steps in it.
bool Simulation::start_glass_sub_step() {
  state_.sim_time_s = static_cast<double>(++state_.sub_steps) * config_.sub_step_s;
  wipers_.advance(config_.sub_step_s, state_.wipers);
  return config_.simulate_water &&
         ++sub_steps_since_water_ >= config_.windshield.sub_steps_per_water_step;
}

void Simulation::step_glass_water() {
  WaterInputs in;
  in.rain_rate_mm_h = state_.weather.rain_rate_mm_h;
  in.air_velocity_mps = air_velocity_vehicle();
  in.blades_before = blades_at_water_step_;
  in.blades_after = wipers_.poses();
  water_.step(sub_steps_since_water_ * config_.sub_step_s, in);
  blades_at_water_step_ = in.blades_after;
  sub_steps_since_water_ = 0;
}

// The ego car and the traffic throw spray from the road's water, each where it is at this
// sub-step: its input is its pose at the end of the advance, so it is moved back along its
// velocity; what crosses the glass becomes drops there.
void Simulation::spray_step(double time_s, std::vector<LandedDrop>& landed) {
  const double ahead = std::clamp(time_s - step_end_s_, -kMaxExtrapolationS, kMaxExtrapolationS);
  std::vector<SpraySource> sources;
  sources.reserve(state_.traffic.size() + 1);
  auto add = [&](std::uint32_t key, const VehicleState& state, glm::dvec3 size,
                 VehicleClass vehicle_class) {
    SpraySource s{key, state, size, vehicle_class};
    s.state.position_m += state.velocity_mps * ahead;
    sources.push_back(s);
  };
  add(0, state_.vehicle, spray_ego_size(), VehicleClass::kCar);
  for (const TrafficVehicle& other : state_.traffic)
    add(other.id == UINT32_MAX ? other.id : other.id + 1, other.state, other.size_m,
        other.vehicle_class);
  RoadWaterGround ground(road_);
  if (state_.road_water) {
    ground.set_mean(state_.road_water->mean_water_mm * 1e-3,
                    state_.road_water->mean_standing_mm * 1e-3);
  }
  if (!config_.simulate_water) {
    spray_.step(sources, wind_velocity(state_.weather), ground);
    return;
  }
  // A drop that stays on the glass is kept for the glass's next step (advance()).
  spray_.step(sources, wind_velocity(state_.weather), ground, &config_.windshield.glass,
              [this, &landed](glm::dvec2 uv_mm, double mass_mg) {
                if (!water_.holds(uv_mm, mass_mg)) return false;
                landed.push_back({uv_mm, mass_mg});
                return true;
              });
}

}  // namespace downpour::sim
