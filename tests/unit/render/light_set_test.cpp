// The frame's lamps from the scene (which are lit, where, aimed how) and their binning into screen
// tiles: a lamp in view lands in the tiles around it and no others, one behind the camera in none.
#include "server/render/cpu/light_set.hpp"

#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>
#include <glm/matrix.hpp>
#include <glm/trigonometric.hpp>

#include "server/render/cpu/camera.hpp"
#include "server/sim/vehicle_class.hpp"

namespace downpour::render {
namespace {

sim::SceneState night_scene() {
  sim::SceneState s;
  s.weather.sun_altitude_deg = -20.0;
  s.weather.cloudiness = 0.2;
  s.vehicle.velocity_mps = {20.0, 0.0, 0.0};
  sim::TrafficVehicle ahead;
  ahead.id = 3;
  ahead.state.position_m = {30.0, 0.0, 0.0};
  ahead.state.velocity_mps = {18.0, 0.0, 0.0};
  s.traffic = {ahead};
  s.ego_lights = sim::resolve_lights(std::nullopt, s.weather, false);
  sim::VehicleLights braking = sim::resolve_lights(std::nullopt, s.weather, true);
  braking.left_indicator = true;
  s.traffic_lights = {braking};
  return s;
}

int count(const std::vector<Light>& lights, LampKind kind, int vehicle) {
  int n = 0;
  for (const Light& l : lights) n += l.kind == kind && l.vehicle == vehicle;
  return n;
}

TEST(LightSetTest, AtNightEachCarShowsItsLampsWhereTheyAreAimedWhereTheyShine) {
  sim::SceneState s = night_scene();
  s.sim_time_s = 0.1;  // an indicator's flash is lit in the first half of each 1/1.5 s
  const std::vector<Light> lights = build_lights(s, {}, glm::vec3(0.0f, 0.0f, 1.2f));
  EXPECT_EQ(count(lights, LampKind::kHeadlight, -1), 2) << "the ego car's low beams";
  EXPECT_EQ(count(lights, LampKind::kTail, -1), 2);
  EXPECT_EQ(count(lights, LampKind::kBrake, -1), 0);
  EXPECT_EQ(count(lights, LampKind::kHeadlight, 0), 2);
  EXPECT_EQ(count(lights, LampKind::kBrake, 0), 2) << "the car ahead slows";
  EXPECT_EQ(count(lights, LampKind::kIndicator, 0), 2) << "its left indicator, front and rear";
  for (const Light& l : lights) {
    if (l.kind == LampKind::kHeadlight && l.vehicle == -1) {
      EXPECT_NEAR(l.position.x, 3.6f, 0.01f);
      EXPECT_NEAR(std::abs(l.position.y), 0.62f, 0.01f);
      EXPECT_GT(l.direction.x, 0.99f) << "ahead";
      EXPECT_LT(l.direction.z, 0.0f) << "dipped";
      EXPECT_NEAR(l.intensity_cd.g / (l.range_m * l.range_m), LightSetConfig{}.cutoff_lux, 0.05f);
    }
    if (l.kind == LampKind::kBrake) {
      EXPECT_NEAR(l.position.x, 30.0f - 0.95f * 4.5f / 4.6f, 0.01f) << "scaled to its length";
      EXPECT_LT(l.direction.x, -0.99f) << "backwards, towards us";
      EXPECT_GT(l.intensity_cd.r, 10.0f * l.intensity_cd.g) << "red";
    }
  }
  s.sim_time_s = 0.5;
  EXPECT_EQ(count(build_lights(s, {}, glm::vec3(0.0f)), LampKind::kIndicator, 0), 0)
      << "between flashes";
}

TEST(LightSetTest, EachClassCarriesItsLampsWhereItsShapeHasThem) {
  // A truck and a bus have their headlamps low on a tall front, a motorbike one lamp each way;
  // each scaled with its size.
  sim::SceneState s = night_scene();
  const auto vehicle = [](sim::VehicleClass c, double x, double scale) {
    sim::TrafficVehicle v;
    v.vehicle_class = c;
    v.state.position_m = {x, 0.0, 0.0};
    v.size_m = sim::vehicle_layout(c).size_m * scale;
    return v;
  };
  s.traffic = {vehicle(sim::VehicleClass::kTruck, 30.0, 1.0),
               vehicle(sim::VehicleClass::kBus, 60.0, 1.0),
               vehicle(sim::VehicleClass::kMotorbike, 90.0, 1.1)};
  sim::VehicleLights on;
  on.headlights = sim::Headlights::kLow;
  on.brake = true;
  sim::VehicleLights hazard = on;
  hazard.left_indicator = hazard.right_indicator = true;
  s.traffic_lights = {on, on, hazard};
  s.sim_time_s = 0.1;  // the indicators' flash lit
  const std::vector<Light> lights = build_lights(s, {}, glm::vec3(0.0f));
  EXPECT_EQ(count(lights, LampKind::kIndicator, 2), 4) << "the motorbike's hazards: each side";
  for (int v = 0; v < 3; ++v) {
    EXPECT_EQ(count(lights, LampKind::kHeadlight, v), v == 2 ? 1 : 2) << v;
    EXPECT_EQ(count(lights, LampKind::kBrake, v), v == 2 ? 1 : 2) << v;
  }
  for (const Light& l : lights) {
    if (l.vehicle == 0 && l.kind == LampKind::kHeadlight) {
      EXPECT_NEAR(l.position.x, 30.0f + 8.98f, 0.01f) << "the truck's front";
      EXPECT_NEAR(l.position.z, 0.85f, 0.01f);
    }
    if (l.vehicle == 2 && l.kind == LampKind::kHeadlight) {
      EXPECT_NEAR(l.position.x, 90.0f + 1.7f * 1.1f, 0.01f) << "the motorbike's, scaled";
      EXPECT_NEAR(l.position.y, 0.0f, 1e-6f) << "on its centre line";
    }
  }
}

TEST(LightSetTest, ByDayNothingIsLitAndAtNightTheNearestStreetLights) {
  sim::SceneState day;
  day.weather.sun_altitude_deg = 45.0;
  day.ego_lights = sim::resolve_lights(std::nullopt, day.weather, false);
  const sim::Track& track = sim::Track::built_in();
  const std::vector<sim::StreetLight> street = sim::street_lights(track);
  EXPECT_TRUE(build_lights(day, street, glm::vec3(0.0f)).empty());
  const sim::SceneState night = night_scene();
  const glm::vec3 camera(track.at(100.0).position);
  const std::vector<Light> lights = build_lights(night, street, camera);
  const int n = count(lights, LampKind::kStreet, -1);
  EXPECT_EQ(n, LightSetConfig{}.max_street);
  for (const Light& l : lights) {
    if (l.kind != LampKind::kStreet) continue;
    EXPECT_LE(glm::length(l.position - camera), LightSetConfig{}.street_within_m);
    EXPECT_LT(l.direction.z, -0.99f) << "down";
  }
}

TEST(LightSetTest, ALampLandsInTheTilesAroundItAndOneBehindTheCameraInNone) {
  sim::VehicleState ego;
  const Camera camera = make_camera(sim::view_spec(sim::View::kCockpit, 640, 360), ego);
  const glm::mat4 view_proj = camera.projection * camera.view;
  Light ahead;
  ahead.position = camera.position + glm::vec3(40.0f, 0.0f, 0.0f);
  ahead.range_m = 2.0f;
  Light behind = ahead;
  behind.position = camera.position - glm::vec3(40.0f, 0.0f, 0.0f);
  Light around = ahead;
  around.position = camera.position + glm::vec3(5.0f, 0.0f, 0.0f);
  around.range_m = 50.0f;
  const LightTiles tiles = bin_lights({ahead, behind, around}, view_proj, 640, 360, 16);
  ASSERT_EQ(tiles.tiles_x, 40);
  ASSERT_EQ(tiles.tiles_y, 23);
  const glm::vec4 c = view_proj * glm::vec4(ahead.position, 1.0f);
  const int cx = static_cast<int>((c.x / c.w * 0.5f + 0.5f) * 640.0f) / 16;
  const int cy = static_cast<int>((c.y / c.w * 0.5f + 0.5f) * 360.0f) / 16;
  int with_ahead = 0, with_behind = 0, with_around = 0;
  for (int ty = 0; ty < tiles.tiles_y; ++ty) {
    for (int tx = 0; tx < tiles.tiles_x; ++tx) {
      const std::size_t k = static_cast<std::size_t>(ty) * tiles.tiles_x + tx;
      for (std::uint32_t j = 0; j < tiles.count[k]; ++j) {
        const std::uint32_t i = tiles.lights[tiles.first[k] + j];
        if (i == 0) {
          ++with_ahead;
          EXPECT_LE(std::abs(tx - cx), 3) << "a 2 m lamp 40 m ahead spans a few tiles";
          EXPECT_LE(std::abs(ty - cy), 3);
        }
        with_behind += i == 1;
        with_around += i == 2;
      }
    }
  }
  EXPECT_GT(with_ahead, 0);
  EXPECT_LE(with_ahead, 49);
  EXPECT_EQ(with_behind, 0);
  EXPECT_EQ(with_around, tiles.tiles_x * tiles.tiles_y) << "a lamp whose reach holds the camera";
  EXPECT_EQ(tiles.max_per_tile(), 2u);
}

}  // namespace
}  // namespace downpour::render

namespace downpour::render {
namespace {

// The load at night: the ego car's low beams, 10 cars ahead and beside on the track (their
// head and tail lamps), the 20 street lights nearest: how many lights a 16-pixel tile of the
// driver's view at 640x360 holds, against all of them (a pixel's loop, forward+ against plain
// forward).
TEST(LightSetTest, TheNightsLoadOverlapsInScreenTiles) {
  const sim::Track& track = sim::Track::built_in();
  sim::SceneState s;
  s.weather.sun_altitude_deg = -20.0;
  auto on_track = [&](double along, double lateral, double speed) {
    const sim::TrackFrame f = track.at(along);
    sim::VehicleState v;
    const glm::dvec2 xy = glm::dvec2(f.position) + f.left * lateral;
    v.position_m = {xy.x, xy.y, track.surface_height(along, lateral)};
    v.rotation.yaw_deg = glm::degrees(f.heading_rad);
    v.velocity_mps = glm::dvec3(std::cos(f.heading_rad), std::sin(f.heading_rad), 0.0) * speed;
    return v;
  };
  s.vehicle = on_track(100.0, -5.25, 25.0);
  for (int k = 1; k <= 10; ++k) {
    sim::TrafficVehicle t;
    t.id = static_cast<std::uint32_t>(k);
    t.state = on_track(100.0 + 18.0 * k, k % 2 ? -1.75 : -5.25, 25.0);
    s.traffic.push_back(t);
  }
  s.ego_lights = sim::resolve_lights(std::nullopt, s.weather, false);
  s.traffic_lights.assign(s.traffic.size(), s.ego_lights);
  const Camera camera = make_camera(sim::view_spec(sim::View::kCockpit, 640, 360), s.vehicle);
  const std::vector<Light> lights = build_lights(s, sim::street_lights(track), camera.position);
  const LightTiles tiles = bin_lights(lights, camera.projection * camera.view, 640, 360, 16);
  std::printf(
      "%zu lights (2 low beams, 10 cars' 40 lamps, %d street lights); a 16-pixel tile "
      "holds %.1f on average, %u at most\n",
      lights.size(), count(lights, LampKind::kStreet, -1), tiles.mean_per_tile(),
      tiles.max_per_tile());
  EXPECT_EQ(lights.size(), 2u + 2u + 40u + 20u);
  // The small lamps stay in a few tiles: the tail lamps of the car 180 m ahead.
  std::vector<int> tiles_of(lights.size(), 0);
  for (std::uint32_t i : tiles.lights) ++tiles_of[i];
  for (std::size_t i = 0; i < lights.size(); ++i) {
    if (lights[i].kind == LampKind::kTail && lights[i].vehicle == 9) {
      EXPECT_GT(tiles_of[i], 0);
      EXPECT_LE(tiles_of[i], 4);
    }
  }
  // The big ones overlap: the street lights along the road ahead and the beams of the cars ahead
  // all reach the far road, which a few rows of tiles show. Screen tiles alone leave most of the
  // lights in most tiles (35.7 of 64 on average at a 1 lux cut-off): the lights' drawing needs
  // depth slices or the ground's light gathered apart (the next step).
  EXPECT_LE(tiles.max_per_tile(), lights.size());

  // With depth slices as well (24, exponential from 1 to 500 m): a tile's pixels on the road lie
  // at about the depth where its centre's ray meets the ground, and only the lights whose reach
  // meets that slice count there.
  const glm::mat4 inverse = glm::inverse(camera.projection * camera.view);
  const glm::vec3 forward = -glm::normalize(glm::vec3(glm::inverse(camera.view)[2]));
  double in_slices = 0.0;
  int road_tiles = 0;
  for (int ty = 0; ty < tiles.tiles_y; ++ty) {
    for (int tx = 0; tx < tiles.tiles_x; ++tx) {
      const glm::vec2 ndc((tx + 0.5f) * 16.0f / 320.0f - 1.0f, (ty + 0.5f) * 16.0f / 180.0f - 1.0f);
      const glm::vec4 far = inverse * glm::vec4(ndc, 0.5f, 1.0f);
      const glm::vec3 dir = glm::normalize(glm::vec3(far) / far.w - camera.position);
      if (dir.z > -0.01f) continue;  // the sky
      const float t = (camera.position.z - static_cast<float>(s.vehicle.position_m.z)) / -dir.z;
      const float depth = t * glm::dot(dir, forward);
      const float slice = std::floor(24.0f * std::log(std::max(depth, 1.0f)) / std::log(500.0f));
      const float z0 = std::exp(slice / 24.0f * std::log(500.0f)),
                  z1 = std::exp((slice + 1.0f) / 24.0f * std::log(500.0f));
      const std::size_t k = static_cast<std::size_t>(ty) * tiles.tiles_x + tx;
      for (std::uint32_t j = 0; j < tiles.count[k]; ++j) {
        const Light& l = lights[tiles.lights[tiles.first[k] + j]];
        const float d = glm::dot(l.position - camera.position, forward);
        in_slices += d + l.range_m >= z0 && d - l.range_m <= z1;
      }
      ++road_tiles;
    }
  }
  std::printf("with 24 depth slices, a road tile's slice holds %.1f on average\n",
              in_slices / std::max(road_tiles, 1));
}

}  // namespace
}  // namespace downpour::render

namespace downpour::render {
namespace {

// What the shaders read: the ego car's beams first, no tail lamps, the lamps ahead of the camera
// before those behind it, nearest first; each with the box of ground it lights.
TEST(LightSetTest, PackedLampsPutTheEgoCarsBeamsFirstAndLampsAheadBeforeThoseBehind) {
  // The camera over the track at 300 m, looking along it; the cars of night_scene elsewhere.
  const sim::Track& track = sim::Track::built_in();
  const sim::SceneState s = night_scene();
  const sim::TrackFrame f = track.at(300.0);
  const glm::vec3 camera(f.position + glm::dvec3(0.0, 0.0, 1.2));
  const glm::vec3 forward(std::cos(f.heading_rad), std::sin(f.heading_rad), 0.0f);
  const std::vector<Light> lights = build_lights(s, sim::street_lights(track), camera);
  LampBlock block;
  const PackedLamps packed = pack_lamps(lights, camera, forward, block);
  EXPECT_EQ(packed.ego, 2);
  EXPECT_EQ(packed.count, static_cast<int>(lights.size()) - 4) << "all but the two cars' tails";
  EXPECT_EQ(block.count.x, 2.0f);
  ASSERT_EQ(packed.ground_boxes.size(), static_cast<std::size_t>(packed.count));
  for (int i = 0; i < 2; ++i) {
    EXPECT_NEAR(block.lamp[4 * i].x - s.vehicle.position_m.x, 3.6, 0.01) << "the ego's beams";
    EXPECT_EQ(block.lamp[4 * i + 3].x, 1.0f) << "dipped";
  }
  bool behind_seen = false;
  float last = 0.0f;
  for (int i = 2; i < packed.count; ++i) {
    const glm::vec3 to = glm::vec3(block.lamp[4 * i]) - camera;
    const bool behind = glm::dot(to, forward) < 0.0f;
    if (!behind) {
      EXPECT_FALSE(behind_seen) << "lamp " << i << " ahead after one behind";
      EXPECT_GE(glm::length(to), last - 1e-3f) << "nearest first";
      last = glm::length(to);
    }
    behind_seen = behind_seen || behind;
  }
  EXPECT_TRUE(behind_seen);
}

// A lamp's footprint holds every point of the ground it gives more than the cut, and little else:
// a street light's round pool about its foot, a dipped beam's fan ahead of the car.
TEST(LightSetTest, AFootprintHoldsTheGroundALampLightsAndLittleMore) {
  sim::SceneState s = night_scene();
  const std::vector<Light> lights = build_lights(s, {}, glm::vec3(0.0f));
  Light beam;
  for (const Light& l : lights) {
    if (l.kind == LampKind::kHeadlight && l.vehicle == -1) beam = l;
  }
  Light street;
  street.position = {50.0f, 10.0f, 9.0f};
  street.ground_z = 0.0f;
  street.direction = {0.0f, 0.0f, -1.0f};
  street.intensity_cd = glm::vec3(3000.0f);
  street.cos_inner = std::cos(glm::radians(65.0f));
  street.cos_outer = std::cos(glm::radians(80.0f));
  for (const Light& l : {beam, street}) {
    const glm::vec4 box = lamp_footprint(l, kGroundCutLux);
    ASSERT_LT(box.x, box.z);
    int lit = 0;
    for (float y = -80.0f; y <= 80.0f; y += 0.5f) {
      for (float x = -80.0f; x <= 80.0f; x += 0.5f) {
        const glm::vec2 p = glm::vec2(l.position) + glm::vec2(x, y);
        if (ground_lux(l, p) <= kGroundCutLux) continue;
        ++lit;
        EXPECT_TRUE(p.x >= box.x && p.x <= box.z && p.y >= box.y && p.y <= box.w)
            << "lit at " << x << ", " << y << " outside the box";
      }
    }
    const float area = (box.z - box.x) * (box.w - box.y);
    std::printf("footprint %.1f x %.1f m, %.0f%% of it lit\n", box.z - box.x, box.w - box.y,
                100.0f * lit * 0.25f / area);
    EXPECT_GT(lit * 0.25f, 0.3f * area) << "the box fits the lit ground";
  }
  const glm::vec4 fan = lamp_footprint(beam, kGroundCutLux);
  EXPECT_GT(fan.x, beam.position.x - 1.0f) << "a beam lights the road ahead of the car only";
  EXPECT_NEAR(ground_lux(street, glm::vec2(50.0f, 10.0f)), 3000.0f / 81.0f, 0.5f) << "under it";
}

}  // namespace
}  // namespace downpour::render
