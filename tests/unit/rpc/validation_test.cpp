#include "server/rpc/validation.hpp"

#include <cmath>
#include <limits>
#include <optional>
#include <string>

#include <gtest/gtest.h>

#include "server/rpc/convert.hpp"
#include "tests/support/png_io.hpp"

namespace downpour::rpc {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// An INVALID_ARGUMENT whose message names the field.
::testing::AssertionResult invalid_naming(const grpc::Status& status, const std::string& field) {
  if (status.error_code() != grpc::StatusCode::INVALID_ARGUMENT) {
    return ::testing::AssertionFailure()
           << "code " << status.error_code() << " (" << status.error_message() << ")";
  }
  if (status.error_message().find(field) == std::string::npos) {
    return ::testing::AssertionFailure()
           << "'" << status.error_message() << "' does not name '" << field << "'";
  }
  return ::testing::AssertionSuccess();
}

v1::ViewSpec view(v1::View v, int width = 640, int height = 360) {
  v1::ViewSpec spec;
  spec.set_view(v);
  spec.set_width(width);
  spec.set_height(height);
  return spec;
}

v1::CreateSessionRequest good_request() {
  v1::CreateSessionRequest r;
  *r.add_views() = view(v1::VIEW_COCKPIT);
  return r;
}

grpc::Status create(const v1::CreateSessionRequest& r) {
  session::SessionConfig config;
  sim::Update initial;
  return to_session_config(r, Limits{}, &config, &initial);
}

grpc::Status update(const v1::Update& u) {
  sim::Update out;
  return to_update(u, "update", Limits{}, &out);
}

TEST(ValidationTest, NonFiniteVehiclePosition) {
  for (double bad : {kNaN, kInf, -kInf}) {
    v1::Update u;
    u.mutable_vehicle()->mutable_position_m()->set_y(bad);
    EXPECT_TRUE(invalid_naming(update(u), "update.vehicle.position_m.y")) << bad;
  }
  v1::CreateSessionRequest r = good_request();
  r.mutable_initial()->mutable_vehicle()->mutable_position_m()->set_x(kNaN);
  EXPECT_TRUE(invalid_naming(create(r), "initial.vehicle.position_m.x"));
}

TEST(ValidationTest, EgoGeometryDefaultsAndRanges) {
  v1::CreateSessionRequest r = good_request();
  session::SessionConfig config;
  sim::Update initial;
  ASSERT_TRUE(to_session_config(r, Limits{}, &config, &initial).ok());
  EXPECT_EQ(config.ego.size_m, sim::EgoGeometry{}.size_m);
  EXPECT_EQ(config.ego.wheelbase_m, 2.7);
  EXPECT_EQ(config.views[0].eye_m, sim::EgoGeometry{}.eye_m);
  // A van: longer, taller, the driver higher up and further forward.
  v1::EgoVehicle* ego = r.mutable_ego();
  ego->mutable_size_m()->set_x(5.3);
  ego->mutable_size_m()->set_y(2.0);
  ego->mutable_size_m()->set_z(2.2);
  ego->set_wheelbase_m(3.3);
  ego->set_track_m(1.7);
  ego->mutable_eye_m()->set_x(1.4);
  ego->mutable_eye_m()->set_y(0.4);
  ego->mutable_eye_m()->set_z(1.3);
  ASSERT_TRUE(to_session_config(r, Limits{}, &config, &initial).ok());
  EXPECT_EQ(config.ego.size_m, glm::dvec3(5.3, 2.0, 2.2));
  EXPECT_EQ(config.ego.wheelbase_m, 3.3);
  EXPECT_EQ(config.ego.track_m, 1.7);
  EXPECT_EQ(config.views[0].eye_m, glm::dvec3(1.4, 0.4, 1.3));
  // Out of range, each named.
  auto refused = [&](auto change, const std::string& field) {
    v1::CreateSessionRequest bad = r;
    change(bad.mutable_ego());
    EXPECT_TRUE(invalid_naming(create(bad), field)) << field;
  };
  refused([](v1::EgoVehicle* e) { e->mutable_size_m()->set_x(40.0); }, "ego.size_m.x");
  refused([](v1::EgoVehicle* e) { e->mutable_size_m()->set_z(kNaN); }, "ego.size_m.z");
  refused([](v1::EgoVehicle* e) { e->set_wheelbase_m(5.0); }, "ego.wheelbase_m");
  refused([](v1::EgoVehicle* e) { e->set_track_m(2.5); }, "ego.track_m");
  refused([](v1::EgoVehicle* e) { e->mutable_eye_m()->set_z(1.6); }, "ego.eye_m.z");
}

TEST(ValidationTest, RainRateOutOfRange) {
  for (double bad : {600.0, -1.0, kNaN}) {
    v1::Update u;
    u.mutable_weather()->set_rain_rate_mm_h(bad);
    EXPECT_TRUE(invalid_naming(update(u), "update.weather.rain_rate_mm_h")) << bad;
  }
  v1::Update ok;
  ok.mutable_weather()->set_rain_rate_mm_h(500.0);
  EXPECT_TRUE(update(ok).ok());
}

// The weather's one definition (sim/weather.hpp) names every field of the contract's Weather and
// no other, with its type; the server refuses each field just outside its range, naming it, and
// takes each at its ends.
TEST(ValidationTest, TheWeatherDefinitionIsTheContractsAndBoundsEveryField) {
  const google::protobuf::Descriptor* wire = v1::Weather::descriptor();
  ASSERT_EQ(static_cast<std::size_t>(wire->field_count()), sim::kWeatherFields.size());
  for (const sim::WeatherField& f : sim::kWeatherFields) {
    const std::string name(f.name);
    const google::protobuf::FieldDescriptor* field = wire->FindFieldByName(name);
    ASSERT_NE(field, nullptr) << name;
    EXPECT_EQ(field->cpp_type() == google::protobuf::FieldDescriptor::CPPTYPE_UINT32, f.integer)
        << name;
    EXPECT_GE(f.fallback, f.min) << name;
    EXPECT_LE(f.fallback, f.max) << name;
    auto with = [&](double v) {
      v1::Update u;
      const google::protobuf::Reflection* r = u.mutable_weather()->GetReflection();
      if (f.integer) {
        r->SetUInt32(u.mutable_weather(), field, static_cast<std::uint32_t>(v));
      } else {
        r->SetDouble(u.mutable_weather(), field, v);
      }
      return u;
    };
    for (double end : {f.min, f.max}) {
      sim::Update out;
      ASSERT_TRUE(to_update(with(end), "update", Limits{}, &out).ok()) << name << " " << end;
      ASSERT_TRUE(out.weather);
      EXPECT_EQ(f.get(*out.weather), end) << name;
    }
    if (!f.integer || f.min > 0.0) {
      EXPECT_TRUE(invalid_naming(update(with(f.min - 1.0)), "update.weather." + name)) << name;
    }
    EXPECT_TRUE(invalid_naming(update(with(f.max + 1.0)), "update.weather." + name)) << name;
  }
}

TEST(ValidationTest, ViewSizeOutOfRange) {
  for (int width : {0, 15, 100000}) {
    v1::CreateSessionRequest r;
    *r.add_views() = view(v1::VIEW_COCKPIT, width, 360);
    EXPECT_TRUE(invalid_naming(create(r), "views[0].width")) << width;
  }
  v1::CreateSessionRequest r;
  *r.add_views() = view(v1::VIEW_ROAD);
  *r.add_views() = view(v1::VIEW_RAIN, 640, Limits{}.max_height + 1);
  EXPECT_TRUE(invalid_naming(create(r), "views[1].height"));
  r.mutable_views(1)->set_height(Limits{}.max_height);
  EXPECT_TRUE(create(r).ok());
}

TEST(ValidationTest, JpegQualityAboveOneHundred) {
  v1::CreateSessionRequest r = good_request();
  r.mutable_views(0)->set_jpeg_quality(101);
  EXPECT_TRUE(invalid_naming(create(r), "views[0].jpeg_quality"));
}

TEST(ValidationTest, UnknownEnumValues) {
  v1::CreateSessionRequest bad_view = good_request();
  bad_view.mutable_views(0)->set_view(static_cast<v1::View>(42));
  EXPECT_TRUE(invalid_naming(create(bad_view), "views[0].view"));

  v1::CreateSessionRequest unspecified_view = good_request();
  unspecified_view.mutable_views(0)->set_view(v1::VIEW_UNSPECIFIED);
  EXPECT_TRUE(invalid_naming(create(unspecified_view), "views[0].view"));

  v1::CreateSessionRequest bad_mode = good_request();
  bad_mode.set_mode(static_cast<v1::Mode>(9));
  EXPECT_TRUE(invalid_naming(create(bad_mode), "mode"));

  v1::Update bad_wipers;
  bad_wipers.mutable_wipers()->set_mode(static_cast<v1::WiperMode>(77));
  EXPECT_TRUE(invalid_naming(update(bad_wipers), "update.wipers.mode"));
}

TEST(ValidationTest, ViewCount) {
  v1::CreateSessionRequest none;
  EXPECT_TRUE(invalid_naming(create(none), "views"));

  v1::CreateSessionRequest duplicate;
  *duplicate.add_views() = view(v1::VIEW_COCKPIT);
  *duplicate.add_views() = view(v1::VIEW_ROAD);
  *duplicate.add_views() = view(v1::VIEW_COCKPIT, 320, 180);
  EXPECT_TRUE(invalid_naming(create(duplicate), "views[2].view"));

  v1::CreateSessionRequest five;
  for (v1::View v :
       {v1::VIEW_COCKPIT, v1::VIEW_ROAD, v1::VIEW_WINDSHIELD, v1::VIEW_RAIN, v1::VIEW_COCKPIT}) {
    *five.add_views() = view(v);
  }
  EXPECT_TRUE(invalid_naming(create(five), "views"));
  five.mutable_views()->RemoveLast();
  EXPECT_TRUE(create(five).ok());
}

TEST(ValidationTest, FpsAboveTheLimit) {
  for (double bad : {Limits{}.max_fps + 1.0, -5.0, kNaN, kInf}) {
    v1::CreateSessionRequest r = good_request();
    r.set_fps(bad);
    EXPECT_TRUE(invalid_naming(create(r), "fps")) << bad;
  }
}

TEST(ValidationTest, StepDtMustBePositiveAndFinite) {
  const Limits limits;
  for (double bad : {0.0, -1.0, kNaN, kInf, limits.max_dt_s + 0.5}) {
    EXPECT_TRUE(invalid_naming(check_dt(bad, "dt_s", false, limits), "dt_s")) << bad;
  }
  EXPECT_TRUE(check_dt(1.0 / 30.0, "dt_s", false, limits).ok());
  EXPECT_TRUE(check_dt(limits.max_dt_s, "dt_s", false, limits).ok());
  // Drive allows 0 (update only), nothing below.
  EXPECT_TRUE(check_dt(0.0, "dt_s", true, limits).ok());
  EXPECT_TRUE(invalid_naming(check_dt(-1.0, "dt_s", true, limits), "dt_s"));
  EXPECT_TRUE(invalid_naming(check_dt(kNaN, "dt_s", true, limits), "dt_s"));
}

TEST(ValidationTest, ManualWipers) {
  v1::Update no_angles;
  no_angles.mutable_wipers()->set_mode(v1::WIPER_MANUAL);
  EXPECT_TRUE(invalid_naming(update(no_angles), "update.wipers.blade_angle_deg"));

  v1::Update too_far;
  too_far.mutable_wipers()->set_mode(v1::WIPER_MANUAL);
  too_far.mutable_wipers()->add_blade_angle_deg(10.0);
  too_far.mutable_wipers()->add_blade_angle_deg(200.0);
  EXPECT_TRUE(invalid_naming(update(too_far), "update.wipers.blade_angle_deg[1]"));

  v1::Update three;
  three.mutable_wipers()->set_mode(v1::WIPER_MANUAL);
  for (int i = 0; i < 3; ++i) three.mutable_wipers()->add_blade_angle_deg(10.0);
  EXPECT_TRUE(invalid_naming(update(three), "update.wipers.blade_angle_deg"));

  v1::Update good;
  good.mutable_wipers()->set_mode(v1::WIPER_MANUAL);
  good.mutable_wipers()->add_blade_angle_deg(45.0);
  good.mutable_wipers()->add_blade_angle_deg(50.0);
  sim::Update out;
  ASSERT_TRUE(to_update(good, "update", Limits{}, &out).ok());
  ASSERT_TRUE(out.wipers);
  EXPECT_EQ(out.wipers->mode, sim::WiperMode::kManual);
  EXPECT_EQ(out.wipers->blade_angle_deg, (std::vector<double>{45.0, 50.0}));
}

TEST(ValidationTest, TrafficOverTheLimit) {
  v1::Update u;
  for (int i = 0; i <= Limits{}.max_traffic; ++i) u.add_traffic()->set_id(i);
  EXPECT_TRUE(invalid_naming(update(u), "update.traffic"));
  u.mutable_traffic()->RemoveLast();
  sim::Update out;
  ASSERT_TRUE(to_update(u, "update", Limits{}, &out).ok());
  ASSERT_TRUE(out.traffic);
  EXPECT_EQ(out.traffic->size(), static_cast<std::size_t>(Limits{}.max_traffic));
}

TEST(ValidationTest, BadTrafficVehicleIsNamedByIndex) {
  v1::Update u;
  u.add_traffic();
  u.add_traffic()->mutable_state()->mutable_velocity_mps()->set_x(kNaN);
  EXPECT_TRUE(invalid_naming(update(u), "update.traffic[1].state.velocity_mps.x"));
}

TEST(ValidationTest, TrafficClassesSetTheirSizeUnlessOneIsGiven) {
  v1::Update u;
  u.add_traffic()->set_vehicle_class(v1::VEHICLE_CLASS_TRUCK);
  v1::TrafficVehicle* bike = u.add_traffic();
  bike->set_vehicle_class(v1::VEHICLE_CLASS_MOTORBIKE);
  bike->mutable_size_m()->set_x(2.0);
  bike->mutable_size_m()->set_y(0.7);
  bike->mutable_size_m()->set_z(1.4);
  sim::Update out;
  ASSERT_TRUE(to_update(u, "update", Limits{}, &out).ok());
  EXPECT_EQ((*out.traffic)[0].vehicle_class, sim::VehicleClass::kTruck);
  EXPECT_EQ((*out.traffic)[0].size_m, glm::dvec3(12.0, 2.5, 3.8));
  EXPECT_EQ((*out.traffic)[1].vehicle_class, sim::VehicleClass::kMotorbike);
  EXPECT_EQ((*out.traffic)[1].size_m, glm::dvec3(2.0, 0.7, 1.4));
  u.mutable_traffic(1)->set_vehicle_class(static_cast<v1::VehicleClass>(17));
  EXPECT_TRUE(invalid_naming(update(u), "update.traffic[1].vehicle_class"));
}

TEST(ValidationTest, CameraPoseIsForTheRoadAndCockpitViewsOnly) {
  v1::CreateSessionRequest r;
  *r.add_views() = view(v1::VIEW_WINDSHIELD);
  r.mutable_views(0)->mutable_camera_position_m()->set_x(1.0);
  EXPECT_TRUE(invalid_naming(create(r), "views[0].camera_position_m"));
  // A forward camera behind the glass is a COCKPIT view with a pose.
  v1::CreateSessionRequest dash = good_request();
  dash.mutable_views(0)->mutable_camera_position_m()->set_x(1.9);
  EXPECT_TRUE(create(dash).ok());
}

TEST(ValidationTest, LensSettingsReachTheDomainViewSpec) {
  v1::CreateSessionRequest r;
  v1::ViewSpec dash = view(v1::VIEW_COCKPIT);
  dash.mutable_camera_position_m()->set_x(1.9);
  dash.set_focus_distance_m(0.6);
  dash.set_aperture_mm(0.0);  // a pinhole
  *r.add_views() = dash;
  v1::ViewSpec road = view(v1::VIEW_ROAD);  // no glass in sight: accepted all the same
  road.set_focus_distance_m(10000.0);
  road.set_aperture_mm(50.0);
  *r.add_views() = road;
  v1::ViewSpec windshield = view(v1::VIEW_WINDSHIELD);
  windshield.set_focus_distance_m(0.05);  // the aperture left out
  *r.add_views() = windshield;
  v1::ViewSpec rain = view(v1::VIEW_RAIN);  // no lens; a shutter of its own
  rain.set_exposure_s(0.0);
  *r.add_views() = rain;

  session::SessionConfig config;
  sim::Update initial;
  const grpc::Status status = to_session_config(r, Limits{}, &config, &initial);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_EQ(config.views.size(), 4u);
  EXPECT_EQ(config.views[0].focus_distance_m, 0.6);
  EXPECT_EQ(config.views[0].aperture_mm, 0.0);
  EXPECT_EQ(config.views[1].focus_distance_m, 10000.0);
  EXPECT_EQ(config.views[1].aperture_mm, 50.0);
  EXPECT_EQ(config.views[2].focus_distance_m, 0.05);
  EXPECT_EQ(config.views[2].aperture_mm, std::nullopt);
  EXPECT_EQ(config.views[3].focus_distance_m, std::nullopt);
  EXPECT_EQ(config.views[3].aperture_mm, std::nullopt);
  EXPECT_EQ(config.views[3].exposure_s, 0.0);
  EXPECT_EQ(config.views[0].exposure_s, std::nullopt);
}

TEST(ValidationTest, LensSettingsOutOfRange) {
  for (double bad : {0.0, 0.04, -1.0, 10001.0, kNaN, kInf, -kInf}) {
    v1::CreateSessionRequest r = good_request();
    *r.add_views() = view(v1::VIEW_ROAD);
    r.mutable_views(1)->set_focus_distance_m(bad);
    EXPECT_TRUE(invalid_naming(create(r), "views[1].focus_distance_m")) << bad;
  }
  for (double bad : {-0.5, 50.5, 80.0, kNaN, kInf, -kInf}) {
    v1::CreateSessionRequest r = good_request();
    *r.add_views() = view(v1::VIEW_ROAD);
    r.mutable_views(1)->set_aperture_mm(bad);
    EXPECT_TRUE(invalid_naming(create(r), "views[1].aperture_mm")) << bad;
  }
  for (double bad : {-0.001, 0.26, 1.0, kNaN, kInf}) {
    v1::CreateSessionRequest r = good_request();
    *r.add_views() = view(v1::VIEW_ROAD);
    r.mutable_views(1)->set_exposure_s(bad);
    EXPECT_TRUE(invalid_naming(create(r), "views[1].exposure_s")) << bad;
  }
  v1::CreateSessionRequest r = good_request();
  *r.add_views() = view(v1::VIEW_ROAD);
  r.mutable_views(1)->set_aperture_mm(80.0);
  EXPECT_EQ(create(r).error_message(), "views[1].aperture_mm: must be in [0, 50], got 80");
  r.mutable_views(1)->set_aperture_mm(4.0);
  r.mutable_views(1)->set_focus_distance_m(kNaN);
  EXPECT_EQ(create(r).error_message(),
            "views[1].focus_distance_m: must be a finite number, got nan");
}

TEST(ValidationTest, SessionInfoEchoesTheLensWhenSet) {
  v1::CreateSessionRequest r;
  *r.add_views() = view(v1::VIEW_COCKPIT);
  r.mutable_views(0)->set_focus_distance_m(1.5);
  r.mutable_views(0)->set_aperture_mm(0.0);
  *r.add_views() = view(v1::VIEW_WINDSHIELD);
  r.mutable_views(1)->set_aperture_mm(2.5);
  *r.add_views() = view(v1::VIEW_RAIN);
  session::SessionConfig config;
  sim::Update initial;
  ASSERT_TRUE(to_session_config(r, Limits{}, &config, &initial).ok());
  const session::Session session("s1", 1, config, initial, [] {});
  v1::SessionInfo info;
  fill_session_info(session, &info);
  ASSERT_EQ(info.views_size(), 3);
  ASSERT_TRUE(info.views(0).has_focus_distance_m());
  EXPECT_EQ(info.views(0).focus_distance_m(), 1.5);
  ASSERT_TRUE(info.views(0).has_aperture_mm());  // 0 (a pinhole) is set, not absent
  EXPECT_EQ(info.views(0).aperture_mm(), 0.0);
  EXPECT_FALSE(info.views(1).has_focus_distance_m());
  ASSERT_TRUE(info.views(1).has_aperture_mm());
  EXPECT_EQ(info.views(1).aperture_mm(), 2.5);
  EXPECT_FALSE(info.views(2).has_focus_distance_m());
  EXPECT_FALSE(info.views(2).has_aperture_mm());
}

TEST(ValidationTest, SessionId) {
  EXPECT_TRUE(invalid_naming(check_session_id("", "session_id"), "session_id"));
  EXPECT_TRUE(invalid_naming(check_session_id(std::string(65, 'a'), "session_id"), "session_id"));
  EXPECT_TRUE(check_session_id("s1-0123abcd", "session_id").ok());
}

TEST(ValidationTest, DefaultsAreFilledIn) {
  v1::CreateSessionRequest r = good_request();
  r.set_seed(77);
  session::SessionConfig config;
  sim::Update initial;
  ASSERT_TRUE(to_session_config(r, Limits{}, &config, &initial).ok());
  EXPECT_EQ(config.mode, sim::Mode::kRealtime);  // MODE_UNSPECIFIED
  EXPECT_EQ(config.fps, 30.0);                   // fps 0
  EXPECT_EQ(config.seed, 77u);
  ASSERT_EQ(config.views.size(), 1u);
  EXPECT_EQ(config.views[0].view, sim::View::kCockpit);
  EXPECT_EQ(config.views[0].width, 640);
  EXPECT_EQ(config.views[0].height, 360);
  EXPECT_EQ(config.views[0].jpeg_quality, 85);  // jpeg_quality 0
  EXPECT_EQ(config.views[0].fov_deg, 0.0);
  EXPECT_FALSE(config.views[0].camera);
  EXPECT_FALSE(config.views[0].focus_distance_m);  // absent: the view's own lens
  EXPECT_FALSE(config.views[0].aperture_mm);
  // An empty initial update carries no channels.
  EXPECT_FALSE(initial.vehicle);
  EXPECT_FALSE(initial.wipers);
  EXPECT_FALSE(initial.weather);
  EXPECT_FALSE(initial.traffic);
}

TEST(ValidationTest, GoodInputsConvertToDomainValues) {
  v1::CreateSessionRequest r;
  *r.add_views() = view(v1::VIEW_WINDSHIELD, 320, 180);
  v1::ViewSpec road = view(v1::VIEW_ROAD, 1280, 720);
  road.set_jpeg_quality(70);
  road.set_fov_deg(60.0);
  road.mutable_camera_position_m()->set_x(-6.0);
  road.mutable_camera_rotation()->set_pitch_deg(10.0);
  *r.add_views() = road;
  r.set_mode(v1::MODE_LOCKSTEP);
  r.set_fps(60.0);
  v1::Update* u = r.mutable_initial();
  u->set_sim_time_s(3.5);
  v1::VehicleState* v = u->mutable_vehicle();
  v->mutable_position_m()->set_x(100.0);
  v->mutable_position_m()->set_y(-20.0);
  v->mutable_rotation()->set_yaw_deg(90.0);
  v->mutable_velocity_mps()->set_x(25.0);
  u->mutable_wipers()->set_mode(v1::WIPER_INTERMITTENT);
  u->mutable_wipers()->set_interval_s(6.0);
  u->mutable_weather()->set_rain_rate_mm_h(25.0);
  u->mutable_weather()->set_cloudiness(0.9);
  u->mutable_weather()->set_rain_streak_count(1000);
  v1::TrafficVehicle* t = u->add_traffic();
  t->set_id(9);
  t->mutable_state()->mutable_position_m()->set_x(130.0);

  session::SessionConfig config;
  sim::Update initial;
  const grpc::Status status = to_session_config(r, Limits{}, &config, &initial);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(config.mode, sim::Mode::kLockstep);
  EXPECT_EQ(config.fps, 60.0);
  ASSERT_EQ(config.views.size(), 2u);
  EXPECT_EQ(config.views[0].view, sim::View::kWindshield);
  EXPECT_EQ(config.views[1].view, sim::View::kRoad);
  EXPECT_EQ(config.views[1].width, 1280);
  EXPECT_EQ(config.views[1].jpeg_quality, 70);
  EXPECT_EQ(config.views[1].fov_deg, 60.0);
  ASSERT_TRUE(config.views[1].camera);
  EXPECT_EQ(config.views[1].camera->position_m, glm::dvec3(-6.0, 0.0, 0.0));
  EXPECT_EQ(config.views[1].camera->rotation.pitch_deg, 10.0);

  EXPECT_EQ(initial.client_time_s, 3.5);
  ASSERT_TRUE(initial.vehicle);
  EXPECT_EQ(initial.vehicle->position_m, glm::dvec3(100.0, -20.0, 0.0));
  EXPECT_EQ(initial.vehicle->rotation.yaw_deg, 90.0);
  EXPECT_EQ(initial.vehicle->velocity_mps, glm::dvec3(25.0, 0.0, 0.0));
  ASSERT_TRUE(initial.wipers);
  EXPECT_EQ(initial.wipers->mode, sim::WiperMode::kIntermittent);
  EXPECT_EQ(initial.wipers->interval_s, 6.0);
  ASSERT_TRUE(initial.weather);
  EXPECT_EQ(initial.weather->rain_rate_mm_h, 25.0);
  EXPECT_EQ(initial.weather->cloudiness, 0.9);
  EXPECT_EQ(initial.weather->rain_streak_count, 1000u);
  ASSERT_TRUE(initial.traffic);
  ASSERT_EQ(initial.traffic->size(), 1u);
  EXPECT_EQ((*initial.traffic)[0].id, 9u);
  EXPECT_EQ((*initial.traffic)[0].state.position_m.x, 130.0);
  EXPECT_EQ((*initial.traffic)[0].size_m, glm::dvec3(4.6, 1.8, 1.47));  // zero size = a car's
}

TEST(ValidationTest, WiperIntervalDefaultsAndRange) {
  v1::Update u;
  u.mutable_wipers()->set_mode(v1::WIPER_INTERMITTENT);
  sim::Update out;
  ASSERT_TRUE(to_update(u, "update", Limits{}, &out).ok());
  EXPECT_EQ(out.wipers->interval_s, 4.0);
  u.mutable_wipers()->set_interval_s(kNaN);
  EXPECT_TRUE(invalid_naming(update(u), "update.wipers.interval_s"));
  u.mutable_wipers()->set_interval_s(120.0);
  EXPECT_TRUE(invalid_naming(update(u), "update.wipers.interval_s"));
}

TEST(ValidationTest, ReplaceTrafficWithAnEmptyListClearsIt) {
  v1::Update u;
  sim::Update out;
  ASSERT_TRUE(to_update(u, "update", Limits{}, &out).ok());
  EXPECT_FALSE(out.traffic);  // absent: keep the list
  u.set_replace_traffic(true);
  ASSERT_TRUE(to_update(u, "update", Limits{}, &out).ok());
  ASSERT_TRUE(out.traffic);
  EXPECT_TRUE(out.traffic->empty());
}

}  // namespace
}  // namespace downpour::rpc

namespace downpour::rpc {
namespace {

TEST(ValidationTest, VehicleLightsAbsentAreAutomaticPresentAreTaken) {
  v1::Update u;
  u.mutable_vehicle()->mutable_position_m()->set_x(1.0);
  sim::Update out;
  ASSERT_TRUE(to_update(u, "update", Limits{}, &out).ok());
  EXPECT_FALSE(out.vehicle->lights.has_value()) << "absent: automatic";

  v1::VehicleLights* l = u.mutable_vehicle()->mutable_lights();
  l->set_headlights(v1::HEADLIGHTS_HIGH);
  l->set_brake(true);
  l->set_left_indicator(true);
  v1::TrafficVehicle* t = u.add_traffic();
  t->set_id(4);
  t->mutable_state()->mutable_lights()->set_right_indicator(true);
  ASSERT_TRUE(to_update(u, "update", Limits{}, &out).ok());
  ASSERT_TRUE(out.vehicle->lights.has_value());
  EXPECT_EQ(out.vehicle->lights->headlights, sim::Headlights::kHigh);
  EXPECT_TRUE(out.vehicle->lights->brake);
  EXPECT_TRUE(out.vehicle->lights->left_indicator);
  EXPECT_FALSE(out.vehicle->lights->right_indicator);
  ASSERT_EQ(out.traffic->size(), 1u);
  ASSERT_TRUE((*out.traffic)[0].state.lights.has_value());
  EXPECT_EQ((*out.traffic)[0].state.lights->headlights, sim::Headlights::kAuto);
  EXPECT_TRUE((*out.traffic)[0].state.lights->right_indicator);
}

TEST(ValidationTest, UnknownHeadlightsAreNamed) {
  v1::Update u;
  u.mutable_vehicle()->mutable_lights()->set_headlights(static_cast<v1::Headlights>(9));
  EXPECT_TRUE(invalid_naming(update(u), "update.vehicle.lights.headlights"));
  v1::Update t;
  t.add_traffic()->mutable_state()->mutable_lights()->set_headlights(
      static_cast<v1::Headlights>(-1));
  EXPECT_TRUE(invalid_naming(update(t), "update.traffic[0].state.lights.headlights"));
}

// A session whose COCKPIT (48 x 20) draws over the client's pictures, and a ROAD view that does
// not.
std::vector<sim::ViewSpec> picture_views() {
  sim::ViewSpec cockpit = sim::view_spec(sim::View::kCockpit, 48, 20);
  cockpit.background = sim::Background::kClient;
  return {cockpit, sim::view_spec(sim::View::kRoad, 48, 20)};
}

std::string grey_png(int width, int height, std::uint8_t level = 128) {
  return testing::png_bytes_rgb(
      width, height,
      std::vector<std::uint8_t>(static_cast<std::size_t>(width) * height * 3, level));
}

v1::ClientImage* add_picture(v1::Update* u, v1::View view, std::string image) {
  v1::ClientImage* c = u->add_client_images();
  c->set_view(view);
  c->set_image(std::move(image));
  return c;
}

TEST(ValidationTest, AWindshieldOverPicturesTakesTheirCamerasPose) {
  v1::CreateSessionRequest r = good_request();
  *r.mutable_views(0) = view(v1::VIEW_WINDSHIELD);
  r.mutable_views(0)->mutable_camera_position_m()->set_x(1.5);
  session::SessionConfig config;
  sim::Update initial;
  EXPECT_TRUE(invalid_naming(to_session_config(r, Limits{}, &config, &initial),
                             "views[0].camera_position_m"));
  r.mutable_views(0)->set_background(v1::BACKGROUND_CLIENT);
  ASSERT_TRUE(to_session_config(r, Limits{}, &config, &initial).ok());
  ASSERT_TRUE(config.views[0].camera.has_value());
  EXPECT_DOUBLE_EQ(config.views[0].camera->position_m.x, 1.5);
}

TEST(ValidationTest, TheBackgroundIsTakenAndEchoed) {
  v1::CreateSessionRequest r = good_request();
  r.mutable_views(0)->set_background(v1::BACKGROUND_CLIENT);
  session::SessionConfig config;
  sim::Update initial;
  ASSERT_TRUE(to_session_config(r, Limits{}, &config, &initial).ok());
  EXPECT_EQ(config.views[0].background, sim::Background::kClient);
  r.mutable_views(0)->set_background(static_cast<v1::Background>(7));
  EXPECT_TRUE(invalid_naming(to_session_config(r, Limits{}, &config, &initial), "background"));
  v1::CreateSessionRequest rain = good_request();
  *rain.mutable_views(0) = view(v1::VIEW_RAIN);
  rain.mutable_views(0)->set_background(v1::BACKGROUND_CLIENT);
  EXPECT_TRUE(invalid_naming(to_session_config(rain, Limits{}, &config, &initial), "background"));
}

TEST(ValidationTest, OutputsAreTakenOnceEach) {
  v1::CreateSessionRequest r = good_request();
  r.mutable_views(0)->add_outputs(v1::OUTPUT_WATER_MASK);
  r.mutable_views(0)->add_outputs(v1::OUTPUT_DEPTH);
  session::SessionConfig config;
  sim::Update initial;
  ASSERT_TRUE(to_session_config(r, Limits{}, &config, &initial).ok());
  EXPECT_EQ(config.views[0].outputs, (sim::Outputs{false, true, true}));
  r.mutable_views(0)->add_outputs(v1::OUTPUT_DEPTH);
  EXPECT_TRUE(
      invalid_naming(to_session_config(r, Limits{}, &config, &initial), "views[0].outputs[2]"));
  r.mutable_views(0)->clear_outputs();
  r.mutable_views(0)->add_outputs(static_cast<v1::Output>(9));
  EXPECT_TRUE(
      invalid_naming(to_session_config(r, Limits{}, &config, &initial), "views[0].outputs[0]"));
}

TEST(ValidationTest, HazeIsForViewsOverPictures) {
  v1::CreateSessionRequest r = good_request();
  r.mutable_views(0)->set_haze(true);
  session::SessionConfig config;
  sim::Update initial;
  EXPECT_TRUE(invalid_naming(to_session_config(r, Limits{}, &config, &initial), "views[0].haze"));
  r.mutable_views(0)->set_background(v1::BACKGROUND_CLIENT);
  ASSERT_TRUE(to_session_config(r, Limits{}, &config, &initial).ok());
  EXPECT_TRUE(config.views[0].haze);
}

TEST(ValidationTest, ClientPicturesAreDecodedWithTheirDepth) {
  v1::Update u;
  std::vector<std::uint16_t> cm(48 * 20, 250);
  cm[0] = 0;  // the sky
  v1::ClientImage* c = add_picture(&u, v1::VIEW_COCKPIT, grey_png(48, 20, 200));
  c->set_depth(testing::png_bytes_grey16(48, 20, cm));
  c->set_depth_encoding(v1::DEPTH_PNG16_CM);
  sim::Update out;
  ASSERT_TRUE(to_client_images(u, "update", picture_views(), &out).ok());
  const auto& image = out.client_images[static_cast<int>(sim::View::kCockpit)];
  ASSERT_TRUE(image);
  EXPECT_EQ(image->width, 48);
  EXPECT_EQ(image->bgrx.size(), 48u * 20u * 4u);
  EXPECT_EQ(image->bgrx[5], 200);
  ASSERT_EQ(image->depth_m.size(), 48u * 20u);
  // (The first pixel of the PNG is the top-left; the server's rows run bottom-up.)
  const std::size_t top_left = 19u * 48u;
  EXPECT_FLOAT_EQ(image->depth_m[top_left], 0.0f);
  EXPECT_FLOAT_EQ(image->depth_m[top_left + 1], 2.5f);
  EXPECT_FLOAT_EQ(image->depth_m[0], 2.5f);
  EXPECT_GT(image->serial, 0u);
  // CARLA's depth camera: (R + 256 G + 65536 B) / (2^24 - 1) of 1000 m; full scale is the sky.
  v1::Update carla;
  std::vector<std::uint8_t> encoded(48 * 20 * 3, 0);
  const std::uint32_t ten_m = 167772;  // 10 m: 0.01 of full scale
  encoded[3] = ten_m & 0xff, encoded[4] = (ten_m >> 8) & 0xff, encoded[5] = ten_m >> 16;
  encoded[0] = encoded[1] = encoded[2] = 0xff;
  v1::ClientImage* d = add_picture(&carla, v1::VIEW_COCKPIT, grey_png(48, 20));
  d->set_depth(testing::png_bytes_rgb(48, 20, encoded));
  d->set_depth_encoding(v1::DEPTH_CARLA_RGB);
  sim::Update out2;
  ASSERT_TRUE(to_client_images(carla, "update", picture_views(), &out2).ok());
  const auto& d2 = out2.client_images[static_cast<int>(sim::View::kCockpit)]->depth_m;
  EXPECT_FLOAT_EQ(d2[top_left], 0.0f);
  EXPECT_NEAR(d2[top_left + 1], 10.0f, 1e-3f);
  EXPECT_GT(out2.client_images[0]->serial, image->serial);
}

TEST(ValidationTest, BadClientPicturesAreRefusedNamingWhatIsWrong) {
  auto refused = [](const v1::Update& u, const std::string& field, const std::string& why) {
    sim::Update out;
    const grpc::Status s = to_client_images(u, "update", picture_views(), &out);
    EXPECT_TRUE(invalid_naming(s, field));
    EXPECT_NE(s.error_message().find(why), std::string::npos) << s.error_message();
    for (const auto& image : out.client_images) EXPECT_FALSE(image) << "nothing taken";
  };
  {
    v1::Update u;
    add_picture(&u, v1::VIEW_COCKPIT, grey_png(64, 20));
    refused(u, "update.client_images[0].image", "the PNG is 64x20, the view is 48x20");
  }
  {
    v1::Update u;
    add_picture(&u, v1::VIEW_COCKPIT, "not a picture at all");
    refused(u, "update.client_images[0].image", "neither a JPEG nor a PNG");
  }
  {
    v1::Update u;  // a good one first: the bad second fails the whole update
    add_picture(&u, v1::VIEW_COCKPIT, grey_png(48, 20));
    add_picture(&u, v1::VIEW_ROAD, grey_png(48, 20));
    refused(u, "update.client_images[1].view", "BACKGROUND_CLIENT");
  }
  {
    v1::Update u;
    add_picture(&u, v1::VIEW_WINDSHIELD, grey_png(48, 20));
    refused(u, "update.client_images[0].view", "the session has no view");
  }
  {
    v1::Update u;
    add_picture(&u, v1::VIEW_COCKPIT, grey_png(48, 20));
    add_picture(&u, v1::VIEW_COCKPIT, grey_png(48, 20));
    refused(u, "update.client_images[1].view", "at most one picture a view");
  }
  {
    v1::Update u;
    v1::ClientImage* c = add_picture(&u, v1::VIEW_COCKPIT, grey_png(48, 20));
    c->set_depth(testing::png_bytes_grey16(48, 21, std::vector<std::uint16_t>(48 * 21, 1)));
    c->set_depth_encoding(v1::DEPTH_PNG16_CM);
    refused(u, "update.client_images[0].depth", "the PNG is 48x21");
  }
  {
    v1::Update u;
    v1::ClientImage* c = add_picture(&u, v1::VIEW_COCKPIT, grey_png(48, 20));
    c->set_depth(testing::png_bytes_grey16(48, 20, std::vector<std::uint16_t>(48 * 20, 1)));
    refused(u, "update.client_images[0].depth_encoding", "DEPTH_PNG16_CM or DEPTH_CARLA_RGB");
  }
  {
    v1::Update u;
    v1::ClientImage* c = add_picture(&u, v1::VIEW_COCKPIT, grey_png(48, 20));
    c->set_depth(grey_png(48, 20));
    c->set_depth_encoding(v1::DEPTH_PNG16_CM);
    refused(u, "update.client_images[0].depth", "not a 16-bit grey PNG");
  }
  {
    v1::Update u;
    v1::ClientImage* c = add_picture(&u, v1::VIEW_COCKPIT, grey_png(48, 20));
    c->set_depth_encoding(v1::DEPTH_CARLA_RGB);
    refused(u, "update.client_images[0].depth", "empty, but a depth_encoding is given");
  }
}

}  // namespace
}  // namespace downpour::rpc
