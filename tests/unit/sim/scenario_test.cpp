#include "server/sim/scenario.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include "server/sim/track.hpp"

namespace downpour::sim {
namespace {

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

VehicleState vehicle_at(glm::dvec3 position, double yaw_deg) {
  VehicleState v;
  v.position_m = position;
  v.rotation.yaw_deg = yaw_deg;
  return v;
}

// Two vehicle keyframes 10 s apart, wipers at t = 0 and t = 4, weather on neither.
Scenario two_keyframes() {
  Scenario s;
  s.duration_s = 10.0;
  s.keyframes.push_back(
      {0.0, vehicle_at({0, 0, 0}, 170.0), WiperState{WiperMode::kLow, 4.0, {}}, std::nullopt});
  s.keyframes.push_back({4.0, std::nullopt, WiperState{WiperMode::kHigh, 4.0, {}}, std::nullopt});
  s.keyframes.push_back({10.0, vehicle_at({100, -20, 5}, -170.0), std::nullopt, std::nullopt});
  return s;
}

// The message of the std::runtime_error that from_json throws, or "" when it throws nothing.
std::string from_json_error(const std::string& text) {
  try {
    Scenario::from_json(text);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

double angle_deg_diff(double a, double b) { return std::remainder(a - b, 360.0); }

TEST(ScenarioTest, AtKeyframesGivesTheKeyframes) {
  const Scenario s = two_keyframes();
  const Update u0 = s.at(0.0);
  ASSERT_TRUE(u0.vehicle);
  EXPECT_EQ(u0.vehicle->position_m, glm::dvec3(0, 0, 0));
  EXPECT_NEAR(angle_deg_diff(u0.vehicle->rotation.yaw_deg, 170.0), 0.0, 1e-12);
  const Update u10 = s.at(10.0);
  ASSERT_TRUE(u10.vehicle);
  EXPECT_EQ(u10.vehicle->position_m, glm::dvec3(100, -20, 5));
  EXPECT_NEAR(angle_deg_diff(u10.vehicle->rotation.yaw_deg, -170.0), 0.0, 1e-12);
  EXPECT_EQ(u10.client_time_s, 10.0);
}

TEST(ScenarioTest, PositionIsLinearBetweenKeyframes) {
  const Scenario s = two_keyframes();
  for (double t : {1.0, 2.5, 5.0, 9.0}) {
    const Update u = s.at(t);
    ASSERT_TRUE(u.vehicle);
    const glm::dvec3 expected = glm::dvec3(100, -20, 5) * (t / 10.0);
    EXPECT_LT(glm::length(u.vehicle->position_m - expected), 1e-9) << "t=" << t;
  }
}

TEST(ScenarioTest, YawTakesTheShortestArc) {
  const Scenario s = two_keyframes();
  // 170 -> -170 turns 20 degrees through 180, not 340 degrees through 0.
  EXPECT_NEAR(angle_deg_diff(s.at(5.0).vehicle->rotation.yaw_deg, 180.0), 0.0, 1e-9);
  EXPECT_NEAR(angle_deg_diff(s.at(2.5).vehicle->rotation.yaw_deg, 175.0), 0.0, 1e-9);
  EXPECT_NEAR(angle_deg_diff(s.at(7.5).vehicle->rotation.yaw_deg, -175.0), 0.0, 1e-9);
  for (double t = 0.0; t <= 10.0; t += 0.25) {
    const double yaw = s.at(t).vehicle->rotation.yaw_deg;
    // Never near 0: the arc stays within 10 degrees of 180.
    EXPECT_LE(std::abs(angle_deg_diff(yaw, 180.0)), 10.0 + 1e-9) << "t=" << t;
  }
}

TEST(ScenarioTest, WipersAreHeldFromTheLastKeyframeAtOrBeforeT) {
  const Scenario s = two_keyframes();
  EXPECT_EQ(s.at(0.0).wipers->mode, WiperMode::kLow);
  EXPECT_EQ(s.at(3.999).wipers->mode, WiperMode::kLow);
  EXPECT_EQ(s.at(4.0).wipers->mode, WiperMode::kHigh);
  EXPECT_EQ(s.at(9.0).wipers->mode, WiperMode::kHigh);
}

TEST(ScenarioTest, AbsentChannelsStayAbsent) {
  const Scenario s = two_keyframes();
  for (double t : {0.0, 3.0, 10.0}) {
    const Update u = s.at(t);
    EXPECT_FALSE(u.weather) << "t=" << t;
    EXPECT_FALSE(u.traffic) << "t=" << t;
    EXPECT_TRUE(u.vehicle) << "t=" << t;
    EXPECT_TRUE(u.wipers) << "t=" << t;
  }
  EXPECT_FALSE(Scenario{}.at(1.0).vehicle);
}

TEST(ScenarioTest, ValuesAreHeldOutsideTheKeyframes) {
  Scenario s = two_keyframes();
  s.loop = false;
  EXPECT_EQ(s.at(-5.0).vehicle->position_m, glm::dvec3(0, 0, 0));
  EXPECT_EQ(s.at(25.0).vehicle->position_m, glm::dvec3(100, -20, 5));
  EXPECT_EQ(s.at(25.0).wipers->mode, WiperMode::kHigh);
}

TEST(ScenarioTest, ChannelInterpolatesBetweenTheKeyframesThatCarryIt) {
  Scenario s;
  s.duration_s = 10.0;
  Weather dry;
  Weather wet;
  wet.rain_rate_mm_h = 20.0;
  s.keyframes.push_back({0.0, vehicle_at({0, 0, 0}, 0.0), std::nullopt, dry});
  s.keyframes.push_back({5.0, vehicle_at({5, 0, 0}, 0.0), std::nullopt, std::nullopt});
  s.keyframes.push_back({10.0, vehicle_at({10, 0, 0}, 0.0), std::nullopt, wet});
  // The middle keyframe has no weather: 7.5 s is three quarters from the first to the last.
  EXPECT_NEAR(s.at(7.5).weather->rain_rate_mm_h, 15.0, 1e-12);
  EXPECT_NEAR(s.at(7.5).vehicle->position_m.x, 7.5, 1e-12);
}

TEST(ScenarioTest, LoopWraps) {
  Scenario s = two_keyframes();
  s.loop = true;
  const Update a = s.at(2.5);
  const Update b = s.at(12.5);
  const Update c = s.at(-7.5);
  EXPECT_LT(glm::length(a.vehicle->position_m - b.vehicle->position_m), 1e-9);
  EXPECT_LT(glm::length(a.vehicle->position_m - c.vehicle->position_m), 1e-9);
  EXPECT_EQ(b.wipers->mode, WiperMode::kLow);
  // The client's clock is not wrapped.
  EXPECT_EQ(b.client_time_s, 12.5);
  EXPECT_EQ(s.at(10.0).vehicle->position_m, glm::dvec3(0, 0, 0));
}

TEST(ScenarioTest, JsonRoundTripOfTheStandardScene) {
  const Scenario original = highway_heavy_rain();
  const Scenario copy = Scenario::from_json(original.to_json());
  EXPECT_EQ(copy.name, original.name);
  EXPECT_EQ(copy.description, original.description);
  EXPECT_EQ(copy.loop, original.loop);
  EXPECT_EQ(copy.seed, original.seed);
  EXPECT_DOUBLE_EQ(copy.duration_s, original.duration_s);
  EXPECT_DOUBLE_EQ(copy.fps, original.fps);
  ASSERT_EQ(copy.views.size(), original.views.size());
  for (std::size_t i = 0; i < copy.views.size(); ++i) {
    EXPECT_EQ(copy.views[i].view, original.views[i].view);
    EXPECT_EQ(copy.views[i].width, original.views[i].width);
    EXPECT_EQ(copy.views[i].height, original.views[i].height);
    EXPECT_EQ(copy.views[i].jpeg_quality, original.views[i].jpeg_quality);
    EXPECT_EQ(copy.views[i].fov_deg, original.views[i].fov_deg);
  }
  ASSERT_EQ(copy.keyframes.size(), original.keyframes.size());
  const double tol = 1e-4;
  for (std::size_t i = 0; i < copy.keyframes.size(); ++i) {
    const Keyframe& a = original.keyframes[i];
    const Keyframe& b = copy.keyframes[i];
    EXPECT_NEAR(a.t, b.t, 1e-6) << "keyframe " << i;
    ASSERT_EQ(a.vehicle.has_value(), b.vehicle.has_value()) << "keyframe " << i;
    ASSERT_EQ(a.wipers.has_value(), b.wipers.has_value()) << "keyframe " << i;
    ASSERT_EQ(a.weather.has_value(), b.weather.has_value()) << "keyframe " << i;
    if (a.vehicle) {
      for (int k = 0; k < 3; ++k) {
        EXPECT_NEAR(a.vehicle->position_m[k], b.vehicle->position_m[k], tol) << "keyframe " << i;
        EXPECT_NEAR(a.vehicle->velocity_mps[k], b.vehicle->velocity_mps[k], tol)
            << "keyframe " << i;
      }
      EXPECT_NEAR(a.vehicle->rotation.yaw_deg, b.vehicle->rotation.yaw_deg, tol);
      EXPECT_NEAR(a.vehicle->rotation.pitch_deg, b.vehicle->rotation.pitch_deg, tol);
      EXPECT_NEAR(a.vehicle->rotation.roll_deg, b.vehicle->rotation.roll_deg, tol);
    }
    if (a.wipers) {
      EXPECT_EQ(a.wipers->mode, b.wipers->mode);
      EXPECT_DOUBLE_EQ(a.wipers->interval_s, b.wipers->interval_s);
      EXPECT_EQ(a.wipers->blade_angle_deg, b.wipers->blade_angle_deg);
    }
    if (a.weather) {
      EXPECT_DOUBLE_EQ(a.weather->rain_rate_mm_h, b.weather->rain_rate_mm_h);
      EXPECT_DOUBLE_EQ(a.weather->wind_speed_mps, b.weather->wind_speed_mps);
      EXPECT_DOUBLE_EQ(a.weather->wind_direction_deg, b.weather->wind_direction_deg);
      EXPECT_DOUBLE_EQ(a.weather->fog_density, b.weather->fog_density);
      EXPECT_DOUBLE_EQ(a.weather->cloudiness, b.weather->cloudiness);
      EXPECT_DOUBLE_EQ(a.weather->sun_altitude_deg, b.weather->sun_altitude_deg);
      EXPECT_DOUBLE_EQ(a.weather->sun_azimuth_deg, b.weather->sun_azimuth_deg);
      EXPECT_EQ(a.weather->rain_streak_count, b.weather->rain_streak_count);
      EXPECT_DOUBLE_EQ(a.weather->rain_angle_deg, b.weather->rain_angle_deg);
    }
  }
  // Written twice, the text is the same: the rounding is stable.
  EXPECT_EQ(copy.to_json(), original.to_json());
}

TEST(ScenarioTest, JsonRoundTripKeepsManualWiperAngles) {
  Scenario s;
  s.keyframes.push_back(
      {0.0, std::nullopt, WiperState{WiperMode::kManual, 2.0, {12.5, 80.0}}, std::nullopt});
  const Scenario copy = Scenario::from_json(s.to_json());
  ASSERT_EQ(copy.keyframes.size(), 1u);
  ASSERT_TRUE(copy.keyframes[0].wipers);
  EXPECT_EQ(copy.keyframes[0].wipers->mode, WiperMode::kManual);
  EXPECT_EQ(copy.keyframes[0].wipers->blade_angle_deg, (std::vector<double>{12.5, 80.0}));
  EXPECT_FALSE(copy.keyframes[0].vehicle);
  EXPECT_FALSE(copy.keyframes[0].weather);
}

TEST(ScenarioTest, FromJsonErrorsNameTheField) {
  EXPECT_PRED2(contains, from_json_error(R"({"keyframes": [{"t": "x"}]})"), "keyframes[0].t");
  EXPECT_PRED2(contains, from_json_error(R"({"keyframes": [{"t": 0}, {"t": 2}, {"t": 1}]})"),
               "keyframes[2].t");
  EXPECT_PRED2(contains, from_json_error(R"({"keyframes": [{"t": 2}, {"t": 1}]})"), "sorted");
  EXPECT_PRED2(contains,
               from_json_error(R"({"keyframes": [{"t": 0, "vehicle": {"position_m": [1, 2]}}]})"),
               "keyframes[0].vehicle.position_m");
  EXPECT_PRED2(
      contains,
      from_json_error(R"({"keyframes": [{"t": 0}, {"t": 1, "wipers": {"mode": "FAST"}}]})"),
      "keyframes[1].wipers.mode");
  EXPECT_PRED2(
      contains,
      from_json_error(R"({"keyframes": [{"t": 0, "weather": {"rain_rate_mm_h": "lots"}}]})"),
      "keyframes[0].weather.rain_rate_mm_h");
  EXPECT_PRED2(contains, from_json_error(R"({"views": [{"view": "SIDE"}]})"), "views[0].view");
  EXPECT_PRED2(contains, from_json_error(R"({"fps": 0})"), "fps");
  EXPECT_PRED2(contains, from_json_error(R"({"fps": -1})"), "fps");
  EXPECT_PRED2(contains, from_json_error("{not json"), "JSON");
  EXPECT_PRED2(contains, from_json_error("[1, 2]"), "object");
  // Equal times are allowed (a step change).
  EXPECT_EQ(from_json_error(R"({"keyframes": [{"t": 1}, {"t": 1}]})"), "");
}

TEST(ScenarioTest, TopLevelFieldErrorsNameTheFieldPlainly) {
  const std::string message = from_json_error(R"({"duration_s": "long"})");
  EXPECT_PRED2(contains, message, "duration_s");
  EXPECT_EQ(message.rfind("scenario duration_s:", 0), 0u) << message;
}

TEST(ScenarioTest, FromJsonThrowsRuntimeErrorForWrongTypes) {
  // The contract (scenario.hpp): throws std::runtime_error naming the field. Wrong JSON types in
  // fields read with json::value() escape as nlohmann::json::type_error instead.
  const char* const cases[][2] = {
      {R"({"name": 5})", "name"},
      {R"({"loop": "yes"})", "loop"},
      {R"({"views": [{"view": 3}]})", "views[0].view"},
      {R"({"keyframes": [{"t": 0, "wipers": {"blade_angle_deg": "up"}}]})",
       "keyframes[0].wipers.blade_angle_deg"},
      // Overflow is nlohmann::json::out_of_range, which the parse_error handler does not catch.
      {R"({"fps": 1e999})", "JSON"},
  };
  std::string failures;
  for (const auto& [text, field] : cases) {
    try {
      Scenario::from_json(text);
      failures += std::string(text) + ": no exception; ";
    } catch (const std::runtime_error& e) {
      if (std::string(e.what()).find(field) == std::string::npos) {
        failures += std::string(text) + ": message does not name " + field + "; ";
      }
    } catch (const std::exception& e) {
      failures += std::string(text) + ": threw a non-runtime_error: " + e.what() + "; ";
    }
  }
  EXPECT_EQ(failures, "");
}

TEST(ScenarioTest, FromJsonRejectsNumbersItCannotConvert) {
  // width, height, jpeg_quality and rain_streak_count are cast from double to an integer type;
  // a value outside that type is undefined behaviour (UBSan) and a garbage size, so it must be
  // refused with the field named.
  const char* const cases[][2] = {
      {R"({"views": [{"view": "COCKPIT", "width": 1e12}]})", "views[0].width"},
      {R"({"views": [{"view": "COCKPIT", "height": -1e12}]})", "views[0].height"},
      {R"({"keyframes": [{"t": 0, "weather": {"rain_streak_count": -5}}]})",
       "keyframes[0].weather.rain_streak_count"},
  };
  std::string failures;
  for (const auto& [text, field] : cases) {
    const std::string message = from_json_error(text);
    if (!contains(message, field)) failures += std::string(text) + ": accepted; ";
  }
  EXPECT_EQ(failures, "");
}

class StandardSceneTest : public ::testing::Test {
 protected:
  const Track track_ = Track::test_track();
};

TEST_F(StandardSceneTest, HighwayHeavyRainSettings) {
  const Scenario s = highway_heavy_rain();
  EXPECT_EQ(s.name, "highway_heavy_rain");
  EXPECT_TRUE(s.loop);
  ASSERT_FALSE(s.keyframes.empty());
  ASSERT_FALSE(s.views.empty());
  EXPECT_DOUBLE_EQ(s.duration_s, s.keyframes.back().t);
  // One lap of the outer lane: the centreline plus a full turn at the lane's offset.
  const double lane_length = track_.length() + 2.0 * std::numbers::pi * -track_.lane_centre(1);
  EXPECT_NEAR(s.duration_s, lane_length / 25.0, 0.1);
  // Weather and wipers hold for the whole lap.
  for (double t : {0.0, s.duration_s * 0.3, s.duration_s * 0.99}) {
    const Update u = s.at(t);
    ASSERT_TRUE(u.weather);
    ASSERT_TRUE(u.wipers);
    EXPECT_EQ(u.weather->rain_rate_mm_h, 25.0);
    EXPECT_EQ(u.wipers->mode, WiperMode::kHigh);
  }
  // Sorted keyframes, about 0.5 s apart.
  for (std::size_t i = 1; i < s.keyframes.size(); ++i) {
    const double dt = s.keyframes[i].t - s.keyframes[i - 1].t;
    EXPECT_GT(dt, 0.0);
    EXPECT_LE(dt, 0.5 + 1e-9);
  }
}

TEST_F(StandardSceneTest, HighwayHeavyRainKeyframesLieOnTheLaneCentre) {
  const Scenario s = highway_heavy_rain();
  for (std::size_t i = 0; i < s.keyframes.size(); ++i) {
    const VehicleState& v = *s.keyframes[i].vehicle;
    const Track::Projection p = track_.project(glm::dvec2(v.position_m));
    EXPECT_NEAR(p.lateral, track_.lane_centre(1), 0.05) << "keyframe " << i;
    EXPECT_NEAR(v.position_m.z, track_.surface_height(p.s, p.lateral), 0.01) << "keyframe " << i;
  }
  // The loop closes onto the first keyframe.
  EXPECT_LT(
      glm::length(s.keyframes.front().vehicle->position_m - s.keyframes.back().vehicle->position_m),
      1e-3);
}

TEST_F(StandardSceneTest, HighwayHeavyRainHeadingFollowsTheTrack) {
  const Scenario s = highway_heavy_rain();
  for (std::size_t i = 1; i < s.keyframes.size(); ++i) {
    const glm::dvec3 d =
        s.keyframes[i].vehicle->position_m - s.keyframes[i - 1].vehicle->position_m;
    const double travel_deg = std::atan2(d.y, d.x) * 180.0 / std::numbers::pi;
    const double yaw0 = s.keyframes[i - 1].vehicle->rotation.yaw_deg;
    const double yaw1 = s.keyframes[i].vehicle->rotation.yaw_deg;
    const double mid_yaw = yaw0 + angle_deg_diff(yaw1, yaw0) / 2.0;
    EXPECT_LT(std::abs(angle_deg_diff(travel_deg, mid_yaw)), 0.5) << "keyframe " << i;
    // Climbing (z grows) is nose up, which is negative pitch.
    if (d.z > 0.01) {
      EXPECT_LT(s.keyframes[i].vehicle->rotation.pitch_deg, 0.0) << "keyframe " << i;
    }
  }
}

// The lane's position moves at speed * (R + offset) / R on the curves when s is the centreline's
// arc length; returns the worst relative deviation from the nominal speed and where it was.
std::pair<double, std::size_t> worst_speed_error(const Scenario& s, double speed) {
  double worst = 0.0;
  std::size_t where = 0;
  for (std::size_t i = 1; i < s.keyframes.size(); ++i) {
    const double dt = s.keyframes[i].t - s.keyframes[i - 1].t;
    const double distance =
        glm::length(s.keyframes[i].vehicle->position_m - s.keyframes[i - 1].vehicle->position_m);
    const double error = std::abs(distance / dt - speed) / speed;
    if (error > worst) {
      worst = error;
      where = i;
    }
  }
  return {worst, where};
}

TEST_F(StandardSceneTest, HighwayHeavyRainDrivesAt25MetresPerSecond) {
  const Scenario s = highway_heavy_rain();
  // The velocity the keyframes declare is 25 m/s along the track.
  for (const Keyframe& k : s.keyframes) {
    EXPECT_NEAR(glm::length(glm::dvec2(k.vehicle->velocity_mps)), 25.0, 1e-9);
  }
  const auto [worst, where] = worst_speed_error(s, 25.0);
  EXPECT_LT(worst, 0.01) << "keyframe " << where;
}

TEST_F(StandardSceneTest, CityDrizzleSettings) {
  const Scenario s = city_drizzle();
  EXPECT_EQ(s.name, "city_drizzle");
  const Update u = s.at(1.0);
  ASSERT_TRUE(u.weather);
  ASSERT_TRUE(u.wipers);
  EXPECT_EQ(u.weather->rain_rate_mm_h, 2.0);
  EXPECT_EQ(u.wipers->mode, WiperMode::kIntermittent);
  for (const Keyframe& k : s.keyframes) {
    const Track::Projection p = track_.project(glm::dvec2(k.vehicle->position_m));
    EXPECT_NEAR(p.lateral, track_.lane_centre(0), 0.05) << "t=" << k.t;
  }
  EXPECT_LT(worst_speed_error(s, 8.0).first, 0.01);
}

}  // namespace
}  // namespace downpour::sim
