#include "server/sim/vehicle_class.hpp"

namespace downpour::sim {

const VehicleLayout& vehicle_layout(VehicleClass c) {
  // A passenger car (the ego car's shape, model/default_models.hpp); a rigid truck with a
  // 7.5 m wheelbase and a box body; a 12 m city bus; a motorbike with its rider.
  static const VehicleLayout kCar{
      {4.6, 1.8, 1.47}, -0.95, {3.6, 0.62, 0.7}, {-0.95, 0.7, 0.78}, 0.33};
  static const VehicleLayout kTruck{
      {12.0, 2.5, 3.8}, -3.0, {8.98, 0.95, 0.85}, {-3.0, 1.05, 0.95}, 0.5};
  static const VehicleLayout kBus{
      {12.0, 2.55, 3.2}, -3.4, {8.58, 1.0, 0.75}, {-3.4, 1.1, 1.0}, 0.5};
  static const VehicleLayout kMotorbike{
      {2.2, 0.8, 1.5}, -0.45, {1.7, 0.0, 0.95}, {-0.45, 0.0, 0.8}, 0.32};
  switch (c) {
    case VehicleClass::kTruck:
      return kTruck;
    case VehicleClass::kBus:
      return kBus;
    case VehicleClass::kMotorbike:
      return kMotorbike;
    case VehicleClass::kCar:
      break;
  }
  return kCar;
}

glm::dvec3 layout_scale(const TrafficVehicle& v) {
  return v.size_m / vehicle_layout(v.vehicle_class).size_m;
}

}  // namespace downpour::sim
