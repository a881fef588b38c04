// A drive along the built-in track for tests and tools of the spray: the ego car on the inner
// lane at a steady speed, optionally behind a truck at a steady gap, on a road that starts wet,
// in lockstep at 30 frames a second. Header-only; sim/ only.
#pragma once

#include <cmath>
#include <optional>
#include <vector>

#include "server/sim/scenario.hpp"
#include "server/sim/simulation.hpp"
#include "server/sim/track.hpp"
#include "server/sim/worker_thread.hpp"

namespace downpour::testing {

// A vehicle on the track's lane (0: the inner one) at s, driving along it at speed.
inline sim::VehicleState on_track(double s, double speed, int lane = 0) {
  const sim::Track& track = sim::Track::built_in();
  const sim::TrackFrame f = track.at(s);
  const double lateral = track.lane_centre(lane);
  sim::VehicleState v;
  const glm::dvec2 xy = glm::dvec2(f.position) + f.left * lateral;
  v.position_m = glm::dvec3(xy, track.surface_height(s, lateral));
  v.rotation.yaw_deg = f.heading_rad * 180.0 / M_PI;
  v.velocity_mps = glm::dvec3(std::cos(f.heading_rad), std::sin(f.heading_rad), 0.0) * speed;
  return v;
}

inline const glm::dvec3 kTruckSize = sim::kBehindTruckSize_m;

struct SprayDrive {
  double start_s = 400.0;
  double speed_mps = 25.0;
  double seconds = 4.0;
  std::optional<double> truck_gap_m;  // the truck's rear axle this far ahead of the ego's
  struct Other {
    std::uint32_t id = 0;
    double gap_m = 0.0;  // ahead of the ego car
    int lane = 0;
    glm::dvec3 size_m{4.5, 1.8, 1.5};
  };
  std::vector<Other> extra_traffic;  // more vehicles, at the same speed
  double road_water_m = 0.0008;      // on every paved cell at the start (0.8 mm: a film)
  double rain_mm_h = 1.0;
  bool simulate_glass = true;
  std::uint64_t seed = 9;
  sim::WorkerThread* helper = nullptr;  // the step's helper (Simulation::advance), as the server's
};

// Drives; `each` (if given) sees the simulation after every frame.
template <typename Each>
sim::Simulation drive(const SprayDrive& d, Each&& each) {
  sim::SimulationConfig config;
  config.road.initial_m = d.road_water_m;
  config.simulate_water = d.simulate_glass;
  sim::Update start;
  start.vehicle = on_track(d.start_s, d.speed_mps);
  sim::Weather w;
  w.rain_rate_mm_h = d.rain_mm_h;
  start.weather = w;
  sim::Simulation sim(d.seed, start, config);
  double s = d.start_s;
  const int frames = static_cast<int>(std::lround(d.seconds * 30.0));
  for (int k = 0; k < frames; ++k) {
    s += d.speed_mps / 30.0;
    sim::Update u;
    u.client_time_s = (k + 1) / 30.0;
    u.vehicle = on_track(s, d.speed_mps);
    std::vector<sim::TrafficVehicle> traffic;
    if (d.truck_gap_m)
      traffic.push_back({1, on_track(s + *d.truck_gap_m, d.speed_mps), kTruckSize});
    for (const SprayDrive::Other& o : d.extra_traffic)
      traffic.push_back({o.id, on_track(s + o.gap_m, d.speed_mps, o.lane), o.size_m});
    u.traffic = traffic;
    sim.apply(u);
    sim.advance(1.0 / 30.0, d.helper);
    each(sim);
  }
  return sim;
}
inline sim::Simulation drive(const SprayDrive& d) {
  return drive(d, [](const sim::Simulation&) {});
}

}  // namespace downpour::testing
