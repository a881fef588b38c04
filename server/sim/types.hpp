// Domain types shared by every layer: what a simulator tells a session, and what it asks to see.
// Plain data, no GL and no gRPC; rpc/ converts to and from the wire types.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <glm/vec3.hpp>

#include "server/sim/weather.hpp"

// A vehicle's or cabin's model (model/vehicle_model.hpp): what the renderer draws. The simulation
// carries it with the vehicle and never looks inside.
namespace downpour::model {
struct VehicleModel;
}

namespace downpour::sim {

using ModelPtr = std::shared_ptr<const model::VehicleModel>;

// Yaw / pitch / roll in degrees: yaw about world z (counter-clockwise from +x), then pitch about
// the vehicle's y (nose down positive, as ISO 8855), then roll about its x.
struct Rotation {
  double yaw_deg = 0.0;
  double pitch_deg = 0.0;
  double roll_deg = 0.0;
};

enum class Headlights : std::uint8_t { kAuto, kOff, kLow, kHigh };

// A vehicle's lamps (sim/lights.hpp resolves the automatic ones).
struct VehicleLights {
  Headlights headlights = Headlights::kAuto;
  bool brake = false;
  bool left_indicator = false;  // both: the hazard lights
  bool right_indicator = false;
  bool reverse = false;
};

struct VehicleState {
  glm::dvec3 position_m{0.0};  // world frame, ground point under the rear axle centre
  Rotation rotation;
  glm::dvec3 velocity_mps{0.0};         // world frame
  std::optional<VehicleLights> lights;  // absent: automatic
};

enum class WiperMode { kOff, kIntermittent, kLow, kHigh, kSingle, kManual };

struct WiperState {
  WiperMode mode = WiperMode::kOff;
  double interval_s = 4.0;
  std::vector<double> blade_angle_deg;  // kManual: one per blade, from park
};

// What a traffic vehicle is: its shape and where its lamps sit (vehicle_class.hpp).
enum class VehicleClass : std::uint8_t { kCar, kTruck, kBus, kMotorbike };

struct TrafficVehicle {
  std::uint32_t id = 0;
  VehicleState state;
  glm::dvec3 size_m{4.5, 1.8, 1.5};
  VehicleClass vehicle_class = VehicleClass::kCar;
  ModelPtr model{};  // null: its class's built-in model
};

// The road's state under a point (road_water.hpp).
enum class RoadState : std::uint8_t {
  kDry,     // no water to speak of
  kWet,     // water in the surface's texture, little or none standing
  kDrench,  // a film standing on the surface
  kPuddle,  // standing water at least RoadWaterConfig::puddle_m deep
};

// The water under one of the ego car's tires after a step: what a driving simulator needs for
// aquaplaning and grip.
struct TireWater {
  double water_mm = 0.0;     // all the water on the road there (in the texture and standing)
  double standing_mm = 0.0;  // the part standing above the texture
  RoadState state = RoadState::kDry;
};
inline constexpr int kTires = 4;  // front left, front right, rear left, rear right

// Where the ego car is on the session's roads after a step (its pose's reference point): for a
// simulator to check that its roads and the server's agree.
struct EgoPlace {
  std::string road;  // the road's id (the built-in track's: "track")
  double s_m = 0.0;
  double t_m = 0.0;  // left positive, from the road's reference line
  int lane = 0;      // OpenDRIVE's lane id: 1, 2, ... left of the centre lane, -1, -2, ... right
  double lane_offset_m = 0.0;  // from the lane's centre line, left positive
  bool on_road = false;        // on the paved width
};

// A partial update: what is present is applied, what is absent keeps its value.
enum class View { kCockpit = 0, kRoad = 1, kWindshield = 2, kRain = 3 };
inline constexpr int kViewCount = 4;
std::string_view view_name(View view);

// A client's camera picture for a view whose background is the client's (ViewSpec::background),
// decoded: what the view draws its rain, spray and glass water over.
struct ClientImage {
  int width = 0;
  int height = 0;
  // Display-encoded (sRGB) blue, green, red and a byte unused, 4 a pixel (a texture takes them
  // without converting), rows bottom-up (GL's order).
  std::vector<std::uint8_t> bgrx;
  // Along the view's axis (m), rows bottom-up; 0 = the sky or unknown. Empty: none came with it.
  std::vector<float> depth_m;
  std::uint64_t serial = 0;  // a new one each picture decoded (the frames count repeats by it)
};
// The picture a view draws over: one per client-background view of the session, replaced as new
// ones come; shared by copies of the state.
using ClientImages = std::array<std::shared_ptr<const ClientImage>, kViewCount>;

struct Update {
  double client_time_s = 0.0;
  std::optional<VehicleState> vehicle;
  std::optional<WiperState> wipers;
  std::optional<Weather> weather;
  std::optional<std::vector<TrafficVehicle>> traffic;  // present = replaces the list
  ClientImages client_images{};                        // present (non-null) = replaces the view's

  // Later fields win; used to fold several realtime updates into one before a tick.
  void merge_from(const Update& later);
};

struct CameraPose {
  glm::dvec3 position_m{0.0};  // vehicle frame
  Rotation rotation;           // relative to the vehicle frame
};

// The ego car's geometry, from the point on the ground under its rear axle's centre (its pose's
// reference point): the contract's EgoVehicle. The defaults are the car the cabin (its windshield,
// dashboard and bonnet) is built for; another size scales the car seen from outside and its spray,
// not the cabin.
struct EgoGeometry {
  glm::dvec3 size_m{4.6, 1.8, 1.47};  // length, width, height
  double wheelbase_m = 2.7;
  double track_m = 1.56;               // between the wheels' centres across
  glm::dvec3 eye_m{1.05, 0.37, 1.22};  // the driver's eye: the COCKPIT and RAIN views' camera
  ModelPtr body_model;                 // null: the built-in car
  ModelPtr cabin_model;                // null: the built-in cabin round the glass
  // The body as the driver sees it past this session's glass and eye (model::bonnet_for): null
  // where they are the defaults, for which the body is marked already.
  ModelPtr bonnet_model;
};

enum class Background { kRendered, kClient };

// The ground truth a view's frames carry beside the picture (the contract's Output).
struct Outputs {
  bool clean = false;       // the frame without the water (glass water and film, rain, spray)
  bool water_mask = false;  // how much the water changes each pixel (needs the clean frame)
  bool depth = false;       // distance along the view's axis
  bool any() const { return clean || water_mask || depth; }
  // Whether the clean frame is read back: for itself, or to make the mask from.
  bool needs_clean() const { return clean || water_mask; }
  bool operator==(const Outputs&) const = default;
};

struct ViewSpec {
  View view = View::kCockpit;
  int width = 640;
  int height = 360;
  int jpeg_quality = 85;
  double fov_deg = 0.0;  // 0 = the view's default
  // ROAD: an outside camera (absent: the chase camera). COCKPIT: a camera in the cabin instead of
  // the driver's eye (a dash camera).
  std::optional<CameraPose> camera;
  // The lens (beyond the paper): focus distance (m) and aperture diameter (mm); absent, the view's
  // own: the driver's eye focused on the road through a pupil that opens with the dark (about 2 mm
  // by day, render::eye_pupil_mm), a camera of its own focused at 3 m through 2 mm. The water on
  // the glass blurs over its circle of confusion; 0 mm is a pinhole.
  std::optional<double> focus_distance_m;
  std::optional<double> aperture_mm;
  // The exposure (s): a rain streak is a drop's motion during it. Absent: 1/60 s.
  std::optional<double> exposure_s;
  // What lies behind the rain: the server's world, or the client's pictures (ClientImage).
  Background background = Background::kRendered;
  Outputs outputs;
  // Over a client's picture: the server's haze over it by its depth (a simulator may draw its
  // own fog, so off unless asked).
  bool haze = false;
  // The driver's eye in the vehicle frame (the session's EgoGeometry): where the COCKPIT and RAIN
  // views look from without a camera of their own.
  glm::dvec3 eye_m = EgoGeometry{}.eye_m;
};

// A view of this size with every other setting at its default.
ViewSpec view_spec(View view, int width, int height,
                   std::optional<CameraPose> camera = std::nullopt);

enum class Mode { kRealtime, kLockstep };

}  // namespace downpour::sim
