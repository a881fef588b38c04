// Scenario files: a timeline of vehicle pose, wipers and weather keyframes, interpolated. The same
// JSON format is read by the Python client (clients/python/downpour_client/scenario.py).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "server/sim/types.hpp"

namespace downpour::sim {

struct Keyframe {
  double t = 0.0;
  std::optional<VehicleState> vehicle;
  std::optional<WiperState> wipers;
  std::optional<Weather> weather;
};

struct Scenario {
  std::string name;
  std::string description;
  double duration_s = 0.0;
  bool loop = false;
  std::uint64_t seed = 0;
  double fps = 30.0;
  std::vector<ViewSpec> views;
  std::vector<Keyframe> keyframes;  // sorted by t

  // Per channel: linear between the neighbouring keyframes that carry it (rotation along the
  // shortest arc), wipers held from the last keyframe at or before t; held outside the range.
  Update at(double t) const;

  static Scenario from_json(const std::string& text);  // throws std::runtime_error naming the field
  std::string to_json() const;
  // at(t) every step_s from 0 to duration_s, as a JSON array of the channels each sample has:
  // what the test of the C++ and Python readers compares.
  std::string samples_json(double step_s) const;
};

// The scenario's inputs at t with a truck `gap_m` ahead in the ego car's lane, 12 m long: the ego
// car's own pose that much further on its drive (the spray behind it, for the benchmarks, the
// renderer's warm-up and their tests).
Update behind_truck(const Scenario& scenario, double t, double gap_m);
inline const glm::dvec3 kBehindTruckSize_m{12.0, 2.5, 3.8};  // its length, width and height

// The standard scenes, defined once here and used by the benchmarks and the clients.
Scenario highway_heavy_rain();
Scenario city_drizzle();

}  // namespace downpour::sim
