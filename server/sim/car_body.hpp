// The ego car's outer shape where the simulation needs it (rain that lands on the car), in the
// vehicle frame: x forward from the rear axle, y left, z up from the ground. The renderer's car
// (render/vehicle_geometry.cpp) is built to the same figures, so that what lands on it is where it
// is drawn.
#pragma once

namespace downpour::sim::car_body {

// The hull: the lower body, whose flat top is the bonnet ahead of the cabin and the boot behind.
inline constexpr double kHullRearX = -0.9;
inline constexpr double kHullFrontX = 3.6;
inline constexpr double kHullHalfWidth = 0.88;
inline constexpr double kHullTopZ = 0.92;
// The cabin on it, from the rear window's foot to the windshield's; the roof over part of it.
inline constexpr double kCabinRearX = -0.55;
inline constexpr double kCabinFrontX = 2.06;
inline constexpr double kCabinHalfWidth = 0.82;
inline constexpr double kRoofRearX = -0.15;
inline constexpr double kRoofFrontX = 1.35;
inline constexpr double kRoofHalfWidth = 0.71;
inline constexpr double kRoofZ = 1.47;

}  // namespace downpour::sim::car_body
