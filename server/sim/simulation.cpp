#include "server/sim/simulation.hpp"

namespace downpour::sim {

Simulation::Simulation(std::uint64_t seed, const Update& initial, SimulationConfig config)
    : config_(config), seed_(seed) {
  apply(initial);
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
}

void Simulation::sub_step() {
  state_.sim_time_s = static_cast<double>(++state_.sub_steps) * config_.sub_step_s;
}

}  // namespace downpour::sim
