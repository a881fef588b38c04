// The ego car's outer shape where the simulation needs it (rain that lands on the car), in the
// vehicle frame: x forward from the rear axle, y left, z up from the ground. The renderer's car
// (model/default_models.cpp) is built to the same figures, so that what lands on it is where
// it is drawn.
#pragma once

namespace downpour::sim::car_body {

// The hull: the lower body, whose flat top is the bonnet ahead of the cabin and the boot behind.
inline constexpr double kHullRearX = -0.9;
inline constexpr double kHullFrontX = 3.6;
inline constexpr double kHullHalfWidth = 0.88;
inline constexpr double kHullTopZ = 0.92;
inline constexpr double kHullBottomZ = 0.3;  // its underside, before it rises at the ends
// The cabin on it, from the rear window's foot to the windshield's; the roof over part of it.
inline constexpr double kCabinRearX = -0.55;
inline constexpr double kCabinFrontX = 2.06;
inline constexpr double kCabinHalfWidth = 0.82;
inline constexpr double kRoofRearX = -0.15;
inline constexpr double kRoofFrontX = 1.35;
inline constexpr double kRoofHalfWidth = 0.71;
inline constexpr double kRoofZ = 1.47;

// The wheels' contact points: the rear axle is the frame's origin, the front axle a wheelbase
// ahead, each wheel half the track to a side (a mid-size car's 2.7 m and 1.56 m).
inline constexpr double kWheelbase = 2.7;
inline constexpr double kTrackHalfWidth = 0.78;

}  // namespace downpour::sim::car_body
