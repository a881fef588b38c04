#include "server/sim/simulation.hpp"

#include <cmath>

#include <glm/mat3x3.hpp>

#include "server/sim/pose.hpp"

namespace downpour::sim {

Simulation::Simulation(std::uint64_t seed, const Update& initial, SimulationConfig config)
    : config_(config),
      seed_(seed),
      wipers_(config.windshield.wipers),
      water_(config.windshield, seed),
      blades_at_water_step_(wipers_.poses()) {
  state_.glass = config_.windshield.glass;
  apply(initial);
  water_.publish(state_.windshield);
}

void Simulation::apply(const Update& update) {
  state_.client_time_s = update.client_time_s;
  if (update.vehicle) state_.vehicle = *update.vehicle;
  if (update.wipers) state_.wipers = *update.wipers;
  if (update.weather) state_.weather = *update.weather;
  if (update.traffic) state_.traffic = *update.traffic;
}

void Simulation::advance(double dt_s) {
  carry_s_ += dt_s;
  // A small tolerance keeps dt = k * sub_step from losing a step to rounding.
  while (carry_s_ >= config_.sub_step_s * (1.0 - 1e-9)) {
    sub_step();
    carry_s_ -= config_.sub_step_s;
  }
  water_.publish(state_.windshield);
}

glm::dvec3 Simulation::air_velocity_vehicle() const {
  const Weather& w = state_.weather;
  const double dir = w.wind_direction_deg * M_PI / 180.0;
  const glm::dvec3 wind(w.wind_speed_mps * std::cos(dir), w.wind_speed_mps * std::sin(dir), 0.0);
  const glm::dmat3 to_world = rotation_matrix(state_.vehicle.rotation);
  return glm::transpose(to_world) * (wind - state_.vehicle.velocity_mps);
}

void Simulation::sub_step() {
  state_.sim_time_s = static_cast<double>(++state_.sub_steps) * config_.sub_step_s;
  wipers_.advance(config_.sub_step_s, state_.wipers);
  if (!config_.simulate_water ||
      ++sub_steps_since_water_ < config_.windshield.sub_steps_per_water_step) {
    return;
  }
  WaterInputs in;
  in.rain_rate_mm_h = state_.weather.rain_rate_mm_h;
  in.air_velocity_mps = air_velocity_vehicle();
  in.blades_before = blades_at_water_step_;
  in.blades_after = wipers_.poses();
  water_.step(sub_steps_since_water_ * config_.sub_step_s, in);
  blades_at_water_step_ = in.blades_after;
  sub_steps_since_water_ = 0;
}

}  // namespace downpour::sim
