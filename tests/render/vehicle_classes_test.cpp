// The traffic's classes on pictures: a truck, a bus and a motorbike seen from the side stand as
// long and as tall in the image as their sizes say, each in its own shape. The ego car's geometry
// (EgoGeometry): its size seen from outside, its eye in the cabin.
#include <algorithm>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <string>

#include <gtest/gtest.h>
#include <glm/trigonometric.hpp>

#include "server/model/default_models.hpp"
#include "server/model/gltf_model.hpp"
#include "server/render/cpu/camera.hpp"
#include "server/render/model_meshes.hpp"
#include "server/sim/pose.hpp"
#include "server/sim/vehicle_class.hpp"
#include "tests/render/render_fixture.hpp"

namespace downpour::render {
namespace {

using testing::RgbaImage;

constexpr int kWidth = 320;
constexpr int kHeight = 180;

class VehicleClassesTest : public testing::RenderTest {
 protected:
  // A vehicle of class c in the ego car's lane of the built-in track, ahead_m along it from the ego
  // car: its middle there (middle) or its origin, on the road's surface.
  static sim::TrafficVehicle in_lane(const sim::SceneState& s, sim::VehicleClass c, int id,
                                     double ahead_m, bool middle) {
    const sim::Track& track = sim::Track::built_in();
    const double s0 = track.project(glm::dvec2(s.vehicle.position_m), 50.0).s;
    const sim::VehicleLayout& layout = sim::vehicle_layout(c);
    const sim::TrackFrame f =
        track.at(s0 + ahead_m - (middle ? 0.5 * layout.size_m.x + layout.rear_m : 0.0));
    sim::TrafficVehicle v;
    v.id = id;
    v.vehicle_class = c;
    v.size_m = layout.size_m;
    const glm::dvec2 xy = glm::dvec2(f.position) + f.left * track.lane_centre(0);
    v.state.position_m = {xy.x, xy.y, track.surface_height(s0 + ahead_m, track.lane_centre(0))};
    v.state.rotation.yaw_deg = glm::degrees(f.heading_rad);
    return v;
  }
};

TEST_F(VehicleClassesTest, EachClassStandsAsLongAndTallAsItsSize) {
  const sim::SceneState base = dry_scene();
  // The vehicle's middle 25 m ahead in the lane left of the ego car's; the camera 16 m to its
  // right side, 2 m up, looking square at it (the ego car's frame: yaw 90 looks left).
  const sim::ViewSpec spec =
      posed_view(sim::View::kRoad, kWidth, kHeight, {25.0, -12.5, 2.0}, 90.0, 0.0, 40.0);
  const RgbaImage empty = render(spec, base);
  for (const sim::VehicleClass c : {sim::VehicleClass::kCar, sim::VehicleClass::kTruck,
                                    sim::VehicleClass::kBus, sim::VehicleClass::kMotorbike}) {
    const sim::VehicleLayout& layout = sim::vehicle_layout(c);
    sim::SceneState s = base;
    const sim::TrafficVehicle v = in_lane(s, c, 0, 25.0, true);  // silver
    s.traffic = {v};
    s.traffic_lights = {sim::VehicleLights{}};
    const RgbaImage image = render(spec, s);
    const std::string name = "vehicle_class_" + std::to_string(static_cast<int>(c)) + ".png";
    if (const char* dir = std::getenv("DOWNPOUR_TEST_IMAGES"))
      testing::write_png(std::string(dir) + "/" + name, image);
    // The changed pixels' box against the projected box of the vehicle's size.
    int x0 = kWidth, x1 = -1, y0 = kHeight, y1 = -1;
    for (int y = 0; y < kHeight; ++y) {
      for (int x = 0; x < kWidth; ++x) {
        const std::size_t i = (static_cast<std::size_t>(y) * kWidth + x) * 4;
        int d = 0;
        for (int k = 0; k < 3; ++k)
          d = std::max(d, std::abs(image.pixels[i + k] - empty.pixels[i + k]));
        if (d > 6)
          x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
      }
    }
    const Camera camera = make_camera(spec, s.vehicle);
    const glm::dmat4 to_world = sim::vehicle_to_world(v.state);
    const auto pixel = [&](double x, double z) {
      const glm::vec4 w(to_world * glm::dvec4(x, -0.5 * v.size_m.y, z, 1.0));
      const glm::vec4 clip = camera.projection * camera.view * w;
      return glm::vec2((clip.x / clip.w * 0.5f + 0.5f) * kWidth,
                       (0.5f - clip.y / clip.w * 0.5f) * kHeight);
    };
    const glm::vec2 rear_bottom = pixel(layout.rear_m, 0.0);
    const glm::vec2 front_top = pixel(layout.rear_m + layout.size_m.x, layout.size_m.z);
    const float expected_w = std::abs(front_top.x - rear_bottom.x);
    const float expected_h = std::abs(rear_bottom.y - front_top.y);
    std::printf("class %d: %d x %d px, its size %.0f x %.0f px\n", static_cast<int>(c), x1 - x0 + 1,
                y1 - y0 + 1, expected_w, expected_h);
    ASSERT_GE(x1, x0) << "the vehicle shows";
    EXPECT_NEAR(x1 - x0 + 1, expected_w, 0.05 * expected_w + 2.0) << static_cast<int>(c);
    EXPECT_NEAR(y1 - y0 + 1, expected_h, 0.05 * expected_h + 2.0) << static_cast<int>(c);
  }
}

// Each class's model close up, from ahead and behind on its left, by day (written to
// DOWNPOUR_TEST_IMAGES as model_<class>_<front|rear>.png, to be looked at): its wheels turn as it
// rolls and nothing else of it moves. A tenth of a turn changes the wheels' pixels (the spokes
// move) and leaves the body's as they were.
TEST_F(VehicleClassesTest, EachModelsWheelsTurnAsItRolls) {
  const sim::SceneState base = dry_scene();
  for (const sim::VehicleClass c : {sim::VehicleClass::kCar, sim::VehicleClass::kTruck,
                                    sim::VehicleClass::kBus, sim::VehicleClass::kMotorbike}) {
    const sim::VehicleLayout& layout = sim::vehicle_layout(c);
    sim::SceneState s = base;
    const double mid = 25.0;
    const sim::TrafficVehicle v = in_lane(s, c, 4, mid, true);  // dark red
    s.traffic = {v};
    s.traffic_lights = {sim::VehicleLights{}};
    s.traffic_rolled_m = {0.0};
    // From the ego car's frame: ahead of the vehicle and to its right, looking back at it; and
    // behind it, looking ahead.
    const double reach = 0.5 * layout.size_m.x + 1.2 * layout.size_m.z + 2.5;
    const double off = -1.5 * layout.size_m.y - 1.5;
    for (const bool ahead : {true, false}) {
      const glm::dvec3 eye(mid + (ahead ? reach : -reach), off, 1.0 + 0.3 * layout.size_m.z);
      const double yaw = ahead ? 180.0 - 35.0 : 35.0;
      const sim::ViewSpec spec = posed_view(sim::View::kRoad, 640, 360, eye, yaw, -5.0, 34.0);
      const RgbaImage still = render(spec, s);
      const std::string name = std::string("model_") + std::to_string(static_cast<int>(c)) +
                               (ahead ? "_front.png" : "_rear.png");
      if (const char* dir = std::getenv("DOWNPOUR_TEST_IMAGES"))
        testing::write_png(std::string(dir) + "/" + name, still);
      if (ahead) continue;
      sim::SceneState rolled = s;
      rolled.traffic_rolled_m = {0.1 * 2.0 * 3.14159265 * layout.wheel_radius_m};
      const RgbaImage turned = render(spec, rolled);
      // The changed pixels lie where the wheels are drawn: under the wheel tops, near the ground.
      const Camera camera = make_camera(spec, s.vehicle);
      const glm::dmat4 to_world = sim::vehicle_to_world(v.state);
      const glm::vec4 top_clip =
          camera.projection * camera.view *
          glm::vec4(to_world * glm::dvec4(0.0, 0.0, 2.05 * layout.wheel_radius_m, 1.0));
      const float wheel_top_row = (0.5f - top_clip.y / top_clip.w * 0.5f) * 360.0f;
      int changed = 0, above = 0;
      for (int y = 0; y < 360; ++y) {
        for (int x = 0; x < 640; ++x) {
          const std::size_t i = (static_cast<std::size_t>(y) * 640 + x) * 4;
          int d = 0;
          for (int k = 0; k < 3; ++k)
            d = std::max(d, std::abs(turned.pixels[i + k] - still.pixels[i + k]));
          if (d > 12) ++changed, above += y < wheel_top_row - 25.0f;
        }
      }
      std::printf(
          "class %d: a tenth of a turn changes %d pixels, %d of them well above the wheels\n",
          static_cast<int>(c), changed, above);
      EXPECT_GT(changed, 30) << static_cast<int>(c);
      EXPECT_LE(above, changed / 20) << static_cast<int>(c);
    }
  }
}

// A model from a glTF file draws as the built-in one it was written from: the traffic's truck and
// the ego car's cabin, through write_glb and read_gltf, against the built-in path.
TEST_F(VehicleClassesTest, AModelReadFromGltfDrawsAsTheBuiltInOne) {
  sim::SceneState s = dry_scene();
  // 10 m ahead: near enough that the built-in truck is drawn in full, as a named model always is.
  const sim::TrafficVehicle v = in_lane(s, sim::VehicleClass::kTruck, 2, 10.0, false);
  s.traffic = {v};
  s.traffic_lights = {sim::VehicleLights{}};
  const sim::ViewSpec spec = sim::view_spec(sim::View::kCockpit, kWidth, kHeight);
  const RgbaImage built_in = render(spec, s);
  auto read = model::read_gltf(model::write_glb(model::default_vehicle(v.vehicle_class)),
                               model::ModelKind::kVehicle);
  s.traffic[0].model = std::make_shared<const model::VehicleModel>(std::move(read));
  s.traffic[0].size_m = glm::dvec3(s.traffic[0].model->size());
  s.ego.cabin_model = std::make_shared<const model::VehicleModel>(
      model::read_gltf(model::write_glb(model::default_cabin(s.glass)), model::ModelKind::kCabin));
  const RgbaImage from_files = render(spec, s);
  if (const char* dir = std::getenv("DOWNPOUR_TEST_IMAGES")) {
    testing::write_png(std::string(dir) + "/model_built_in.png", built_in);
    testing::write_png(std::string(dir) + "/model_from_gltf.png", from_files);
  }
  double sum = 0.0;
  int worst = 0, off = 0;
  for (std::size_t i = 0; i < built_in.pixels.size(); ++i) {
    if (i % 4 == 3) continue;
    const int d = std::abs(built_in.pixels[i] - from_files.pixels[i]);
    sum += d;
    worst = std::max(worst, d);
    off += d > 8;
  }
  const double mean = sum / (0.75 * static_cast<double>(built_in.pixels.size()));
  std::printf(
      "from glTF against built in: mean difference %.3f levels, %d channels off by more "
      "than 8 (largest %d)\n",
      mean, off, worst);
  EXPECT_LT(mean, 0.05);
  EXPECT_LT(off, 10);
}

// Each built-in model is one draw, its wheels turned in the vertex shader (model_meshes.hpp); a
// model whose wheels do not follow its fixed parts in order is drawn a wheel at a time. Both turn
// the wheels alike: a car seen from its side, rolled 0.37 m, drawn each way.
TEST_F(VehicleClassesTest, WheelsTurnAlikeInTheShaderAndDrawnOneByOne) {
  for (const sim::VehicleClass c : {sim::VehicleClass::kCar, sim::VehicleClass::kTruck,
                                    sim::VehicleClass::kBus, sim::VehicleClass::kMotorbike}) {
    const model::VehicleModel m = model::default_vehicle(c);
    EXPECT_EQ(ModelMesh(m).wheel_vertices.size(), m.wheels.size()) << static_cast<int>(c);
  }
  model::VehicleModel reordered = model::default_vehicle(sim::VehicleClass::kCar);
  std::reverse(reordered.wheels.begin(), reordered.wheels.end());
  ASSERT_TRUE(ModelMesh(reordered).wheel_vertices.empty());

  sim::SceneState s = dry_scene();
  const sim::TrafficVehicle v = in_lane(s, sim::VehicleClass::kCar, 4, 25.0, true);
  s.traffic = {v};
  s.traffic_lights = {sim::VehicleLights{}};
  s.traffic_rolled_m = {0.37};
  const sim::ViewSpec spec =
      posed_view(sim::View::kRoad, 640, 360, glm::dvec3(25.0, -7.0, 1.2), 90.0, -5.0, 34.0);
  const RgbaImage in_shader = render(spec, s);
  s.traffic[0].model = std::make_shared<const model::VehicleModel>(std::move(reordered));
  s.traffic[0].size_m = glm::dvec3(s.traffic[0].model->size());
  const RgbaImage one_by_one = render(spec, s);
  sim::SceneState still = s;
  still.traffic_rolled_m = {0.0};
  const RgbaImage unturned = render(spec, still);
  if (const char* dir = std::getenv("DOWNPOUR_TEST_IMAGES")) {
    testing::write_png(std::string(dir) + "/wheels_in_shader.png", in_shader);
    testing::write_png(std::string(dir) + "/wheels_one_by_one.png", one_by_one);
  }
  int off = 0, worst = 0, turned = 0;
  for (std::size_t i = 0; i < in_shader.pixels.size(); ++i) {
    if (i % 4 == 3) continue;
    const int d = std::abs(in_shader.pixels[i] - one_by_one.pixels[i]);
    worst = std::max(worst, d);
    off += d > 8;
    turned += std::abs(in_shader.pixels[i] - unturned.pixels[i]) > 12;
  }
  std::printf(
      "wheels turned in the shader against one by one: %d channels off by more than 8 (largest "
      "%d); %d channels differ from the wheels unturned\n",
      off, worst, turned);
  EXPECT_GT(turned, 30);  // the wheels did turn
  EXPECT_LT(off, 10);
}

// A vehicle far off is drawn from its model for the distance (plain boxes), shaded as its full
// model is: a truck 90 m ahead, its pixels' mean colour from each model.
TEST_F(VehicleClassesTest, AVehicleForTheDistanceIsShadedAsItsFullModel) {
  sim::SceneState s = dry_scene();
  const sim::TrafficVehicle v = in_lane(s, sim::VehicleClass::kTruck, 5, 90.0, false);  // white
  const sim::ViewSpec spec = sim::view_spec(sim::View::kCockpit, 640, 360);
  const RgbaImage empty = render(spec, s);
  s.traffic = {v};
  s.traffic_lights = {sim::VehicleLights{}};
  const RgbaImage far = render(spec, s);  // under 40 px tall: the model for the distance
  // A named model is drawn in full at any distance.
  s.traffic[0].model =
      std::make_shared<const model::VehicleModel>(model::default_vehicle(v.vehicle_class));
  s.traffic[0].size_m = glm::dvec3(s.traffic[0].model->size());
  const RgbaImage full = render(spec, s);
  if (const char* dir = std::getenv("DOWNPOUR_TEST_IMAGES")) {
    testing::write_png(std::string(dir) + "/model_far.png", far);
    testing::write_png(std::string(dir) + "/model_far_in_full.png", full);
  }
  const auto mean_over = [&](const RgbaImage& image) {
    glm::dvec3 sum(0.0);
    int n = 0;
    for (std::size_t i = 0; i < image.pixels.size(); i += 4) {
      int d = 0;
      for (int k = 0; k < 3; ++k)
        d = std::max(d, std::abs(image.pixels[i + k] - empty.pixels[i + k]));
      if (d <= 12) continue;
      sum += glm::dvec3(image.pixels[i], image.pixels[i + 1], image.pixels[i + 2]);
      ++n;
    }
    return std::make_pair(n, n > 0 ? sum / static_cast<double>(n) : sum);
  };
  const auto [n_far, c_far] = mean_over(far);
  const auto [n_full, c_full] = mean_over(full);
  std::printf(
      "the truck 90 m ahead: %d pixels from the far model, mean %.0f %.0f %.0f; %d in full, "
      "mean %.0f %.0f %.0f\n",
      n_far, c_far.r, c_far.g, c_far.b, n_full, c_full.r, c_full.g, c_full.b);
  ASSERT_GT(n_full, 100);
  EXPECT_NEAR(n_far, n_full, 0.15 * n_full);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(c_far[k], c_full[k], 12.0) << k;
}

// From the driver's seat the bonnet follows the session's glass: with the glass's foot 15 cm
// further back (the cabin built round it), the bonnet shows as much red as with the default glass,
// none of it missing where the default bonnet's triangles would have ended.
TEST_F(VehicleClassesTest, TheBonnetFollowsTheSessionsGlass) {
  const auto red = [](const RgbaImage& image) {
    int n = 0;
    for (std::size_t i = 0; i < image.pixels.size(); i += 4)
      n += image.pixels[i] > image.pixels[i + 1] + 8 && image.pixels[i] > image.pixels[i + 2] + 8;
    return n;
  };
  sim::SceneState s = dry_scene();
  const sim::ViewSpec spec = sim::view_spec(sim::View::kCockpit, 640, 360);
  const RgbaImage usual = render(spec, s);
  ASSERT_EQ(model::bonnet_for(nullptr, s.glass, s.ego.eye_m), nullptr);  // marked already
  s.glass.bottom_left_m.x -= 0.15;
  s.ego.bonnet_model = model::bonnet_for(nullptr, s.glass, s.ego.eye_m);  // as rpc/models.cpp
  const RgbaImage back = render(spec, s);
  if (const char* dir = std::getenv("DOWNPOUR_TEST_IMAGES")) {
    testing::write_png(std::string(dir) + "/bonnet_default_glass.png", usual);
    testing::write_png(std::string(dir) + "/bonnet_glass_back.png", back);
  }
  std::printf("the bonnet's red pixels: %d with the default glass, %d with the glass 15 cm back\n",
              red(usual), red(back));
  EXPECT_GT(red(usual), 2000);
  EXPECT_GT(red(back), red(usual) * 9 / 10);
}

// A model's base-colour texture shows: the white truck 25 m ahead, its every vertex reading a
// texture red on the left half and blue on the right (u = 0.25 on the truck's right side, 0.75
// on its left), its paint times the texture: its rear shows red on the right, blue on the left.
TEST_F(VehicleClassesTest, AModelsTextureShows) {
  sim::SceneState s = dry_scene();
  const sim::ViewSpec spec = sim::view_spec(sim::View::kCockpit, 640, 360);
  const sim::TrafficVehicle v = in_lane(s, sim::VehicleClass::kTruck, 5, 25.0, true);  // white
  auto textured = std::make_shared<model::VehicleModel>(model::default_vehicle(v.vehicle_class));
  constexpr int n = model::kModelTextureSide;
  std::vector<std::uint8_t> layer(static_cast<std::size_t>(n) * n * 4);
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) {
      std::uint8_t* t = &layer[(static_cast<std::size_t>(y) * n + x) * 4];
      t[0] = x < n / 2 ? 255 : 0, t[1] = 0, t[2] = x < n / 2 ? 0 : 255, t[3] = 255;
    }
  }
  textured->textures = {{std::make_shared<const std::vector<std::uint8_t>>(std::move(layer))}};
  for (const render::MeshVertex& vertex : textured->mesh.vertices)
    textured->mesh.texcoords.push_back({{vertex.position.y < 0.0f ? 0.25f : 0.75f, 0.5f}, 0.0f});
  const auto count = [&](bool texture) {
    s.traffic = {v};
    s.traffic[0].model =
        texture
            ? textured
            : std::make_shared<const model::VehicleModel>(model::default_vehicle(v.vehicle_class));
    s.traffic[0].size_m = glm::dvec3(s.traffic[0].model->size());
    s.traffic_lights = {sim::VehicleLights{}};
    const RgbaImage image = render(spec, s);
    if (const char* dir = std::getenv("DOWNPOUR_TEST_IMAGES"))
      testing::write_png(std::string(dir) + (texture ? "/model_textured.png" : "/model_plain.png"),
                         image);
    // The red pixels and the blue, and their mean columns.
    std::array<double, 4> found{};  // red, its mean x, blue, its mean x
    for (int y = 0; y < image.height / 2; ++y) {
      for (int x = 0; x < image.width; ++x) {
        const std::uint8_t* p = &image.pixels[(static_cast<std::size_t>(y) * image.width + x) * 4];
        if (p[0] > p[1] + 40 && p[0] > p[2] + 40) found[0] += 1.0, found[1] += x;
        if (p[2] > p[0] + 40 && p[2] > p[1] + 30) found[2] += 1.0, found[3] += x;
      }
    }
    found[1] /= std::max(found[0], 1.0);
    found[3] /= std::max(found[2], 1.0);
    return found;
  };
  const std::array<double, 4> plain = count(false), painted = count(true);
  std::printf(
      "red pixels (mean column), blue pixels (mean column): %.0f (%.0f), %.0f (%.0f) untextured; "
      "%.0f (%.0f), %.0f (%.0f) with the texture\n",
      plain[0], plain[1], plain[2], plain[3], painted[0], painted[1], painted[2], painted[3]);
  // Red on the truck's right (the view's right, seen from behind), blue on its left.
  EXPECT_GT(painted[0], plain[0] + 500);
  EXPECT_GT(painted[2], plain[2] + 500);
  EXPECT_GT(painted[1], painted[3] + 10.0);
}

// The spray a body stops wets it (sim/spray.hpp), on a dry day too: a silver car 25 m ahead whose
// body the spray has wet through, and the ego car's bonnet likewise, darken as wet paint does.
// (SprayTest.AVehicleStopsTheSprayThatMeetsItAndGetsWet: how the spray wets them.)
TEST_F(VehicleClassesTest, TheSprayABodyStoppedWetsIt) {
  sim::SceneState s = dry_scene();
  s.weather.rain_rate_mm_h = 0.0;  // a dry day: the weather wets nothing
  const sim::ViewSpec spec = sim::view_spec(sim::View::kCockpit, 640, 360);
  const RgbaImage empty = render(spec, s);
  s.traffic = {in_lane(s, sim::VehicleClass::kCar, 0, 25.0, true)};  // silver
  s.traffic_lights = {sim::VehicleLights{}};
  s.traffic_body_wet = {0.0f};
  const RgbaImage dry = render(spec, s);
  s.traffic_body_wet = {1.0f};
  s.ego_body_wet = 1.0f;
  const RgbaImage wet = render(spec, s);
  if (const char* dir = std::getenv("DOWNPOUR_TEST_IMAGES")) {
    testing::write_png(std::string(dir) + "/body_dry.png", dry);
    testing::write_png(std::string(dir) + "/body_wet.png", wet);
  }
  // The car: the pixels it covers (against the empty road), their mean luma dry and wet. The
  // bonnet: the mean red of the red pixels in the view's third quarter from the top.
  double car[2] = {0.0, 0.0}, bonnet[2] = {0.0, 0.0};
  int n_car = 0, n_bonnet = 0;
  for (std::size_t i = 0; i < dry.pixels.size(); i += 4) {
    const std::uint8_t* d = &dry.pixels[i];
    int change = 0;
    for (int k = 0; k < 3; ++k) change = std::max(change, std::abs(d[k] - empty.pixels[i + k]));
    if (change > 12) {
      car[0] += 0.3 * d[0] + 0.59 * d[1] + 0.11 * d[2];
      car[1] += 0.3 * wet.pixels[i] + 0.59 * wet.pixels[i + 1] + 0.11 * wet.pixels[i + 2];
      ++n_car;
    }
    const std::size_t row = i / 4 / static_cast<std::size_t>(spec.width);
    const bool low = row > static_cast<std::size_t>(spec.height / 2) &&
                     row < static_cast<std::size_t>(spec.height * 3 / 4);
    if (change == 0 && low && d[0] > d[1] + 8 && d[0] > d[2] + 8) {
      bonnet[0] += d[0], bonnet[1] += wet.pixels[i], ++n_bonnet;
    }
  }
  ASSERT_GT(n_car, 200);
  ASSERT_GT(n_bonnet, 1000);
  std::printf(
      "the car ahead: mean luma %.1f dry, %.1f wet (%d px); the bonnet's red %.1f dry, "
      "%.1f wet (%d px)\n",
      car[0] / n_car, car[1] / n_car, n_car, bonnet[0] / n_bonnet, bonnet[1] / n_bonnet, n_bonnet);
  // Wet paint darkens (albedo x0.72) and mirrors the bright overcast more (vehicle.frag): 5-6% in
  // all, windows and lamps included; unwetted, both stay as they are.
  EXPECT_LT(car[1], car[0] * 0.97);
  EXPECT_LT(bonnet[1], bonnet[0] * 0.97);
}

// The changed pixels' columns (x0, x1) and rows (y0, y1) of an image against another.
glm::ivec4 changed_box(const RgbaImage& image, const RgbaImage& base) {
  glm::ivec4 box(image.width, -1, image.height, -1);
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const std::size_t i = (static_cast<std::size_t>(y) * image.width + x) * 4;
      int d = 0;
      for (int k = 0; k < 3; ++k)
        d = std::max(d, std::abs(image.pixels[i + k] - base.pixels[i + k]));
      if (d > 24)
        box = {std::min(box.x, x), std::max(box.y, x), std::min(box.z, y), std::max(box.w, y)};
    }
  }
  return box;
}

TEST_F(VehicleClassesTest, TheEgoCarIsAsLongAsItsSizeAndItsDriverSeesFromItsEye) {
  // From its right side, 12 m off, looking square at it: a default car, then one 6.9 m long
  // (1.5 times) and 2 m tall.
  sim::SceneState s = dry_scene();
  const sim::ViewSpec side =
      posed_view(sim::View::kRoad, kWidth, kHeight, {1.3, -12.0, 1.5}, 90.0, 0.0, 40.0);
  sim::SceneState empty = s;
  empty.ego.size_m = glm::dvec3(1e-4);  // out of sight (the camera goes with the car)
  const RgbaImage ground = render(side, empty);
  const glm::ivec4 normal = changed_box(render(side, s), ground);
  s.ego.size_m = {6.9, 1.8, 2.0};
  const glm::ivec4 long_car = changed_box(render(side, s), ground);
  const double length_ratio = static_cast<double>(long_car.y - long_car.x) / (normal.y - normal.x);
  const double height_ratio = static_cast<double>(long_car.w - long_car.z) / (normal.w - normal.z);
  std::printf("ego car 4.6 x 1.47 m: %d x %d px; 6.9 x 2.0 m: %d x %d px (%.2f, %.2f)\n",
              normal.y - normal.x, normal.w - normal.z, long_car.y - long_car.x,
              long_car.w - long_car.z, length_ratio, height_ratio);
  EXPECT_NEAR(length_ratio, 1.5, 0.08);
  EXPECT_NEAR(height_ratio, 2.0 / 1.47, 0.1);
  // The driver's eye 12 cm higher (a tall driver): the bonnet (red) sinks in the COCKPIT view,
  // and the windshield's top edge with the headliner comes down into it.
  sim::SceneState d = dry_scene();
  sim::ViewSpec cockpit = sim::view_spec(sim::View::kCockpit, kWidth, kHeight);
  const glm::dvec3 eye = cockpit.eye_m;
  const RgbaImage low = render(cockpit, d);
  cockpit.eye_m = eye + glm::dvec3(0.0, 0.0, 0.12);
  const RgbaImage high = render(cockpit, d);
  if (const char* dir = std::getenv("DOWNPOUR_TEST_IMAGES")) {
    testing::write_png(std::string(dir) + "/ego_eye_low.png", low);
    testing::write_png(std::string(dir) + "/ego_eye_high.png", high);
  }
  auto bonnet_top = [&](const RgbaImage& image) {
    for (int y = 0; y < kHeight; ++y) {
      const std::size_t i = (static_cast<std::size_t>(y) * kWidth + kWidth / 2) * 4;
      if (image.pixels[i] > image.pixels[i + 1] + 10)
        return y;  // (wet paint: deep red, a sheen of sky)
    }
    return kHeight;
  };
  std::printf("the bonnet's top in the middle column: eye at %.2f m row %d, at %.2f m row %d\n",
              eye.z, bonnet_top(low), eye.z + 0.12, bonnet_top(high));
  EXPECT_GT(bonnet_top(high), bonnet_top(low) + 5);
}

// Rain wets the paint: the car's red, against the sky that lights it, darkens by more than the
// light does (the chase camera's view of the ego car's rear, the same full cloud, dry and in
// 10 mm/h, no streaks to confuse it). The red channel: the paint's own, where the sheen adds grey.
TEST_F(VehicleClassesTest, TheRainDarkensThePaint) {
  auto body_over_sky = [&](double rain_mm_h) {
    sim::SceneState s = dry_scene();
    s.weather.cloudiness = 1.0;
    s.weather.rain_rate_mm_h = rain_mm_h;
    s.spray.reset();
    const RgbaImage image = render(sim::view_spec(sim::View::kRoad, 320, 180), s);
    auto red = [&](int x0, int y0, int x1, int y1) {
      double sum = 0.0;
      for (int y = y0; y < y1; ++y) {
        for (int x = x0; x < x1; ++x)
          sum += image.pixels[(static_cast<std::size_t>(y) * 320 + x) * 4];
      }
      return sum / ((x1 - x0) * (y1 - y0));
    };
    return red(145, 108, 175, 120) / red(0, 5, 320, 20);
  };
  const double dry = body_over_sky(0.0), wet = body_over_sky(10.0);
  std::printf("the paint's red against the sky's: %.3f dry, %.3f in 10 mm/h\n", dry, wet);
  EXPECT_LT(wet, 0.93 * dry);
}

}  // namespace
}  // namespace downpour::render
