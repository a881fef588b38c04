// glTF models: the built-in ones written out and read back give the same triangles, parts and
// places; a hand-written .gltf is read in glTF's axes into the vehicle frame's, placed on its rear
// axle; a cabin's windshield gives the glass's outline; every broken or hostile file is refused
// with a message that says why, and a 200k-triangle model reads in well under a second.
#include <array>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include "server/encode/png_encoder.hpp"
#include "server/model/default_models.hpp"
#include "server/model/gltf_model.hpp"
#include "server/model/materials.hpp"
#include "server/model/shapes.hpp"

namespace downpour::model {
namespace {

std::map<int, std::size_t> triangles_by_material(const VehicleModel& m) {
  std::map<int, std::size_t> out;
  for (std::size_t i = 0; i < m.mesh.indices.size(); i += 3)
    ++out[static_cast<int>(m.mesh.vertices[m.mesh.indices[i]].uv.x + 0.5f)];
  return out;
}

TEST(GltfModelTest, TheBuiltInModelsComeBackAsTheyWereWritten) {
  for (const sim::VehicleClass c : {sim::VehicleClass::kCar, sim::VehicleClass::kTruck,
                                    sim::VehicleClass::kBus, sim::VehicleClass::kMotorbike}) {
    const VehicleModel built = default_vehicle(c);
    const std::string glb = write_glb(built);
    const VehicleModel read = read_gltf(glb, ModelKind::kVehicle);
    std::printf("class %d: %zu triangles, %zu wheels, %zu bytes as glTF\n", static_cast<int>(c),
                built.triangles(), built.wheels.size(), glb.size());
    EXPECT_EQ(read.triangles(), built.triangles());
    EXPECT_EQ(read.fixed_index_count, built.fixed_index_count);
    EXPECT_EQ(triangles_by_material(read), triangles_by_material(built));
    ASSERT_EQ(read.wheels.size(), built.wheels.size());
    // Placed by its rear axle and its lowest point, as built.
    EXPECT_LT(glm::length(read.mesh.bounds_min - built.mesh.bounds_min), 1e-3f);
    EXPECT_LT(glm::length(read.mesh.bounds_max - built.mesh.bounds_max), 1e-3f);
    for (std::size_t w = 0; w < read.wheels.size(); ++w) {
      EXPECT_LT(glm::length(read.wheels[w].centre - built.wheels[w].centre), 0.01f);
      EXPECT_NEAR(read.wheels[w].radius_m, built.wheels[w].radius_m, 0.01f);
    }
  }
}

// A unit cube's 12 triangles in glTF's axes, one material, in a JSON file with its buffer
// embedded; `extra` goes into the top-level object.
std::string base64(const std::string& bytes) {
  static const char* k = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    unsigned v = static_cast<unsigned char>(bytes[i]) << 16;
    if (i + 1 < bytes.size()) v |= static_cast<unsigned char>(bytes[i + 1]) << 8;
    if (i + 2 < bytes.size()) v |= static_cast<unsigned char>(bytes[i + 2]);
    out += k[v >> 18 & 63];
    out += k[v >> 12 & 63];
    out += i + 1 < bytes.size() ? k[v >> 6 & 63] : '=';
    out += i + 2 < bytes.size() ? k[v & 63] : '=';
  }
  return out;
}

// A box in glTF's axes: x across from -w to w, y up from 0 to h, z from z0 to z1 (forward).
std::string box_bytes(float w, float h, float z0, float z1) {
  const float p[8][3] = {{-w, 0, z0}, {w, 0, z0}, {w, h, z0}, {-w, h, z0},
                         {-w, 0, z1}, {w, 0, z1}, {w, h, z1}, {-w, h, z1}};
  const std::uint16_t idx[36] = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                                 3, 7, 6, 3, 6, 2, 0, 4, 7, 0, 7, 3, 1, 2, 6, 1, 6, 5};
  std::string bytes(reinterpret_cast<const char*>(p), sizeof(p));
  bytes.append(reinterpret_cast<const char*>(idx), sizeof(idx));
  return bytes;
}

std::string box_gltf(const std::string& material, const std::string& node_name = "body",
                     const std::string& buffer_uri = "", const std::string& extra = "",
                     int count = 8, float scale = 1.0f) {
  const std::string bytes = box_bytes(0.9f * scale, 1.4f * scale, -1.0f * scale, 3.6f * scale);
  const std::string uri =
      buffer_uri.empty() ? "data:application/octet-stream;base64," + base64(bytes) : buffer_uri;
  return R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],)"
         R"("nodes":[{"name":")" +
         node_name +
         R"(","mesh":0}],)"
         R"("meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1,"material":0}]}],)"
         R"("materials":[{"name":")" +
         material +
         R"("}],)"
         R"("accessors":[{"bufferView":0,"componentType":5126,"count":)" +
         std::to_string(count) +
         R"(,"type":"VEC3","min":[-1,0,-1],"max":[1,1,1]},)"
         R"({"bufferView":1,"componentType":5123,"count":36,"type":"SCALAR"}],)"
         R"("bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":96},)"
         R"({"buffer":0,"byteOffset":96,"byteLength":72}],)"
         R"("buffers":[{"byteLength":168,"uri":")" +
         uri + R"("}])" + extra + "}";
}

// The box with a base-colour texture: a PNG of 2 x 1 pixels, red on the left and blue on the
// right, its vertices on glTF's -x reading u = 0.25 (red), those on +x u = 0.75 (blue). `png`:
// the image's bytes in place of that PNG.
std::string textured_box_gltf(const std::string& material, std::string png = {}) {
  if (png.empty()) {
    const std::uint8_t pixels[6] = {255, 0, 0, 0, 0, 255};
    png = encode::encode_png(pixels, 2, 1, encode::PngFormat::kRgb8, encode::RowOrder::kTopDown);
  }
  std::string bytes = box_bytes(0.9f, 1.4f, -1.0f, 3.6f);
  const float xs[8] = {-1, 1, 1, -1, -1, 1, 1, -1};
  for (float x : xs) {
    const float uv[2] = {x < 0.0f ? 0.25f : 0.75f, 0.5f};
    bytes.append(reinterpret_cast<const char*>(uv), sizeof(uv));
  }
  return R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],)"
         R"("nodes":[{"name":"body","mesh":0}],)"
         R"("meshes":[{"primitives":[{"attributes":{"POSITION":0,"TEXCOORD_0":2},"indices":1,)"
         R"("material":0}]}],)"
         R"("materials":[{"name":")" +
         material +
         R"(","pbrMetallicRoughness":{"baseColorTexture":{"index":0}}}],)"
         R"("textures":[{"source":0}],)"
         R"("images":[{"uri":"data:image/png;base64,)" +
         base64(png) +
         R"("}],)"
         R"("accessors":[{"bufferView":0,"componentType":5126,"count":8,"type":"VEC3",)"
         R"("min":[-1,0,-1],"max":[1,1,1]},)"
         R"({"bufferView":1,"componentType":5123,"count":36,"type":"SCALAR"},)"
         R"({"bufferView":2,"componentType":5126,"count":8,"type":"VEC2"}],)"
         R"("bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":96},)"
         R"({"buffer":0,"byteOffset":96,"byteLength":72},)"
         R"({"buffer":0,"byteOffset":168,"byteLength":64}],)"
         R"("buffers":[{"byteLength":232,"uri":"data:application/octet-stream;base64,)" +
         base64(bytes) + R"("}]})";
}

// A base-colour texture is read: decoded, resampled to a layer (kModelTextureSide square, the
// mean of the pixels each texel covers, in linear light), and each vertex keeps where it reads it.
TEST(GltfModelTest, ABaseColourTextureIsReadIntoALayer) {
  const VehicleModel m = read_gltf(textured_box_gltf("Trim"), ModelKind::kVehicle);
  ASSERT_EQ(m.textures.size(), 1u);
  ASSERT_EQ(m.mesh.texcoords.size(), m.mesh.vertices.size());
  constexpr int n = kModelTextureSide;
  auto texel = [&](int x, int y) {
    const std::uint8_t* t = &(*m.textures[0].rgba)[(static_cast<std::size_t>(y) * n + x) * 4];
    return std::array<int, 4>{t[0], t[1], t[2], t[3]};
  };
  EXPECT_EQ(texel(n / 4, n / 2), (std::array<int, 4>{255, 0, 0, 255}));
  EXPECT_EQ(texel(3 * n / 4, n / 2), (std::array<int, 4>{0, 0, 255, 255}));
  int red = 0, blue = 0;
  for (std::size_t i = 0; i < m.mesh.vertices.size(); ++i) {
    const render::VertexTexture& t = m.mesh.texcoords[i];
    EXPECT_EQ(t.layer, 0.0f);
    // glTF's -x is the vehicle's right (-y): red there.
    if (m.mesh.vertices[i].position.y < 0.0f)
      red += t.uv.x == 0.25f;
    else
      blue += t.uv.x == 0.75f;
  }
  EXPECT_EQ(red + blue, static_cast<int>(m.mesh.vertices.size()));
  // A textured trim's colour is the texture's (times white), not the built-in dark trim.
  EXPECT_EQ(m.mesh.vertices[0].uv.y, pack_trim_colour(1.0, 1.0, 1.0));
  // Paint keeps the vehicle's colour, times the texture.
  const VehicleModel paint = read_gltf(textured_box_gltf("Car_Paint"), ModelKind::kVehicle);
  EXPECT_EQ(paint.mesh.vertices[0].uv.x, material::kBody);
  EXPECT_EQ(paint.textures.size(), 1u);
  // Without TEXCOORD_0 the texture is not used.
  std::string bare = textured_box_gltf("Trim");
  bare.replace(bare.find(R"(,"TEXCOORD_0":2)"), 15, "");
  const VehicleModel untextured = read_gltf(bare, ModelKind::kVehicle);
  EXPECT_TRUE(untextured.textures.empty());
  EXPECT_TRUE(untextured.mesh.texcoords.empty());
}

TEST(GltfModelTest, ABadOrOversizedTextureIsRefusedWithAReason) {
  const auto refusal = [](const std::string& text, const ModelLimits& limits = {}) {
    try {
      read_gltf(text, ModelKind::kVehicle, limits);
    } catch (const ModelError& e) {
      return std::string(e.what());
    }
    return std::string("read");
  };
  const std::string damaged = refusal(textured_box_gltf("Trim", "\x89PNG\r\n\x1a\n broken"));
  const std::string neither = refusal(textured_box_gltf("Trim", "GIF89a"));
  ModelLimits small;
  small.max_image_side = 1;
  const std::string wide = refusal(textured_box_gltf("Trim"), small);
  ModelLimits few;
  few.max_image_pixels = 1;
  const std::string many = refusal(textured_box_gltf("Trim"), few);
  std::printf("%s\n%s\n%s\n%s\n", damaged.c_str(), neither.c_str(), wide.c_str(), many.c_str());
  EXPECT_NE(damaged.find("image 0"), std::string::npos);
  EXPECT_NE(neither.find("neither a JPEG nor a PNG"), std::string::npos);
  EXPECT_NE(wide.find("over the limit of 1x1"), std::string::npos);
  // (From the PNG's header: no pixel is decoded.)
  EXPECT_NE(many.find("2x1, over the 1 pixels left to the model"), std::string::npos);
  // An image in a buffer view that runs past its buffer (tinygltf passes such a range on
  // unchecked): refused, nothing read beyond the buffer.
  std::string viewed = textured_box_gltf("Trim");
  const std::size_t at = viewed.find(R"({"uri":"data:image/png;base64,)");
  const std::size_t end = viewed.find('}', at);
  viewed.replace(at, end - at + 1, R"({"bufferView":3,"mimeType":"image/png"})");
  const std::size_t views = viewed.find(R"({"buffer":0,"byteOffset":168,"byteLength":64})");
  viewed.insert(views + 45, R"(,{"buffer":0,"byteOffset":200,"byteLength":1000000})");
  const std::string outside = refusal(viewed);
  std::printf("%s\n", outside.c_str());
  EXPECT_NE(outside.find("outside its buffer"), std::string::npos);
}

TEST(GltfModelTest, AHandWrittenFileIsReadInTheVehicleFramesAxes) {
  const VehicleModel m = read_gltf(box_gltf("Car_Paint"), ModelKind::kVehicle);
  EXPECT_EQ(m.triangles(), 12u);
  // glTF's z (forward) is the vehicle's x; its y (up) the vehicle's z; its x (left) the y.
  EXPECT_NEAR(m.size().x, 4.6f, 1e-5f);
  EXPECT_NEAR(m.size().y, 1.8f, 1e-5f);
  EXPECT_NEAR(m.size().z, 1.4f, 1e-5f);
  // No wheels: the rear axle a fifth of the length from the rear, the ground under it.
  EXPECT_NEAR(m.mesh.bounds_min.x, -0.92f, 1e-5f);
  EXPECT_NEAR(m.mesh.bounds_min.z, 0.0f, 1e-6f);
  EXPECT_NEAR(m.mesh.bounds_min.y, -0.9f, 1e-5f);
  EXPECT_EQ(triangles_by_material(m), (std::map<int, std::size_t>{{0, 12}}));  // paint
  // Flat normals were made, pointing out of the box.
  for (std::size_t i = 0; i < m.mesh.indices.size(); i += 3) {
    const render::MeshVertex& v = m.mesh.vertices[m.mesh.indices[i]];
    const glm::vec3 centre = 0.5f * (m.mesh.bounds_min + m.mesh.bounds_max);
    EXPECT_GT(glm::dot(v.normal, v.position - centre), 0.0f);
  }
  // Named as a wheel, the same box is one, about its middle.
  const VehicleModel w = read_gltf(box_gltf("rubber", "Wheel_RL"), ModelKind::kVehicle);
  ASSERT_EQ(w.wheels.size(), 1u);
  EXPECT_EQ(w.fixed_index_count, 0u);
  EXPECT_NEAR(w.wheels[0].radius_m, 0.7f, 1e-5f);
  EXPECT_NEAR(w.wheels[0].centre.x, 0.0f, 1e-5f);  // the rear axle: the frame's origin
  EXPECT_EQ(triangles_by_material(w), (std::map<int, std::size_t>{{2, 12}}));  // tyre
}

TEST(GltfModelTest, OtherMaterialsAreTrimOfTheirOwnColour) {
  std::string text = box_gltf("chrome");
  text.replace(text.find(R"({"name":"chrome"})"), 17,
               R"({"name":"chrome","pbrMetallicRoughness":{"baseColorFactor":[1,0.5,0,1]}})");
  const VehicleModel m = read_gltf(text, ModelKind::kVehicle);
  EXPECT_EQ(m.mesh.vertices[0].uv.x, material::kTrim);
  EXPECT_EQ(m.mesh.vertices[0].uv.y, pack_trim_colour(1.0, 0.5, 0.0));
}

TEST(GltfModelTest, BuffersBesideTheFileAreReadAndNothingElse) {
  const std::filesystem::path dir = std::filesystem::path(::testing::TempDir()) / "gltf_beside";
  std::filesystem::create_directories(dir);
  {
    std::ofstream(dir / "box.bin", std::ios::binary) << box_bytes(0.9f, 1.4f, -1.0f, 3.6f);
    std::ofstream(dir / "box.gltf") << box_gltf("paint", "body", "box.bin");
    std::ofstream(dir / "escape.gltf") << box_gltf("paint", "body", "../gltf_beside/box.bin");
    std::ofstream(dir / "absolute.gltf") << box_gltf("paint", "body", "/etc/passwd");
  }
  EXPECT_EQ(read_gltf_file(dir / "box.gltf", ModelKind::kVehicle).triangles(), 12u);
  for (const char* name : {"escape.gltf", "absolute.gltf"}) {
    try {
      read_gltf_file(dir / name, ModelKind::kVehicle);
      ADD_FAILURE() << name << " was read";
    } catch (const ModelError& e) {
      std::printf("%s: %s\n", name, e.what());
    }
  }
  // A texture's image beside the file is read through the same checks.
  {
    std::string text = textured_box_gltf("Trim");
    const std::size_t at = text.find("data:image/png;base64,");
    const std::size_t end = text.find('"', at);
    const std::uint8_t pixels[6] = {255, 0, 0, 0, 0, 255};
    std::ofstream(dir / "red_blue.png", std::ios::binary)
        << encode::encode_png(pixels, 2, 1, encode::PngFormat::kRgb8, encode::RowOrder::kTopDown);
    std::ofstream(dir / "textured.gltf") << text.substr(0, at) + "red_blue.png" + text.substr(end);
    std::ofstream(dir / "escaping_image.gltf")
        << text.substr(0, at) + "../gltf_beside/red_blue.png" + text.substr(end);
  }
  EXPECT_EQ(read_gltf_file(dir / "textured.gltf", ModelKind::kVehicle).textures.size(), 1u);
  EXPECT_THROW(read_gltf_file(dir / "escaping_image.gltf", ModelKind::kVehicle), ModelError);
  // The same text from memory, with nowhere to look beside it.
  EXPECT_THROW(read_gltf(box_gltf("paint", "body", "box.bin"), ModelKind::kVehicle), ModelError);
  EXPECT_THROW(read_gltf_file(dir / "missing.glb", ModelKind::kVehicle), ModelError);
}

// What must be refused, and a word its message must hold.
TEST(GltfModelTest, BrokenAndHostileFilesAreRefusedWithAReason) {
  const std::string good = box_gltf("paint");
  std::string glb = write_glb(default_vehicle(sim::VehicleClass::kCar));
  std::string bad_version = glb;
  bad_version[4] = 3;
  std::string cycle = good;
  cycle.replace(cycle.find(R"("mesh":0})"), 9, R"("mesh":0,"children":[0]})");
  std::string index_past = good;  // 8 vertices said, but an index is 8
  {
    std::string bytes = box_bytes(0.9f, 1.4f, -1.0f, 3.6f);
    bytes[96] = 8;
    index_past = box_gltf("paint", "body", "data:application/octet-stream;base64," + base64(bytes));
  }
  std::string deep = good;
  deep.replace(deep.size() - 1, 1,
               R"(,"extras":)" + std::string(200, '[') + std::string(200, ']') + "}");
  ModelLimits small;
  small.max_triangles = 10;
  struct Case {
    const char* what;
    std::string bytes;
    const char* says;
    ModelLimits limits;
  };
  const std::vector<Case> cases = {
      {"not glTF", "hello", "not a glTF", {}},
      {"empty", "", "not a glTF", {}},
      {"a truncated glb", glb.substr(0, glb.size() / 2), "holds", {}},
      {"glb version 3", bad_version, "version", {}},
      {"an accessor past its view", box_gltf("paint", "body", "", "", 9), "runs past", {}},
      {"an accessor of two billion",
       box_gltf("paint", "body", "", "", 2'000'000'000),
       "runs past",
       {}},
      {"an index past the vertices", index_past, "index", {}},
      {"a cycle of nodes", cycle, "cycle", {}},
      {"too many triangles", good, "more than 10 triangles", small},
      {"JSON nested 200 deep", deep, "deeper", {}},
      {"a required extension",
       box_gltf("paint", "body", "", R"(,"extensionsRequired":["KHR_draco_mesh_compression"])"),
       "extension",
       {}},
      {"millimetres", box_gltf("paint", "body", "", "", 8, 1000.0f), "not a road vehicle", {}},
      {"no mesh", R"({"asset":{"version":"2.0"},"nodes":[{"name":"empty"}]})", "no mesh", {}},
  };
  for (const Case& c : cases) {
    try {
      read_gltf(c.bytes, ModelKind::kVehicle, c.limits);
      ADD_FAILURE() << c.what << " was read";
    } catch (const ModelError& e) {
      std::printf("%s: %s\n", c.what, e.what());
      EXPECT_NE(std::string(e.what()).find(c.says), std::string::npos)
          << c.what << ": " << e.what();
    }
  }
}

TEST(GltfModelTest, TheBuiltInCabinComesBackWithItsGlass) {
  sim::GlassConfig glass;
  glass.rake_deg = 55.0;
  glass.bottom_width_mm = 1450.0;
  const VehicleModel built = default_cabin(glass);
  const VehicleModel read = read_gltf(write_glb(built), ModelKind::kCabin);
  EXPECT_EQ(read.triangles(), built.triangles());
  EXPECT_LT(glm::length(read.mesh.bounds_min - built.mesh.bounds_min), 1e-4f);
  ASSERT_TRUE(read.windshield.has_value());
  const sim::GlassConfig back = glass_of(*read.windshield);
  EXPECT_NEAR(back.bottom_width_mm, 1450.0, 0.5);
  EXPECT_NEAR(back.rake_deg, 55.0, 0.02);
  EXPECT_LT(glm::length(back.bottom_left_m - glass.bottom_left_m), 1e-3);
}

TEST(GltfModelTest, ACabinsWindshieldGivesTheGlasssOutline) {
  // The built-in cabin with the glass's own quad as its windshield, in glTF's axes.
  const sim::GlassConfig glass;
  const double inset = glass.inset_mm(glass.height_mm);
  const glm::dvec3 corners[4] = {glass.to_vehicle({0.0, 0.0}),
                                 glass.to_vehicle({glass.bottom_width_mm, 0.0}),
                                 glass.to_vehicle({glass.bottom_width_mm - inset, glass.height_mm}),
                                 glass.to_vehicle({inset, glass.height_mm})};
  std::string bytes;
  for (const glm::dvec3& c : corners) {
    const float g[3] = {static_cast<float>(c.y), static_cast<float>(c.z), static_cast<float>(c.x)};
    bytes.append(reinterpret_cast<const char*>(g), sizeof(g));
  }
  const std::uint16_t idx[6] = {0, 1, 2, 0, 2, 3};
  bytes.append(reinterpret_cast<const char*>(idx), sizeof(idx));
  const std::string text =
      R"({"asset":{"version":"2.0"},"scenes":[{"nodes":[0]}],"nodes":[{"name":"glass","mesh":0}],)"
      R"("meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1,"material":0}]}],)"
      R"("materials":[{"name":"Windshield"}],)"
      R"("accessors":[{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3"},)"
      R"({"bufferView":1,"componentType":5123,"count":6,"type":"SCALAR"}],)"
      R"("bufferViews":[{"buffer":0,"byteLength":48},{"buffer":0,"byteOffset":48,"byteLength":12}],)"
      R"("buffers":[{"byteLength":60,"uri":"data:application/octet-stream;base64,)" +
      base64(bytes) + R"("}]})";
  const VehicleModel cabin = read_gltf(text, ModelKind::kCabin);
  ASSERT_TRUE(cabin.windshield.has_value());
  const WindshieldOutline& w = *cabin.windshield;
  std::printf(
      "outline: %.1f x %.1f (top %.1f) mm, rake %.2f deg, bow %.2f mm, foot (%.3f, %.3f, %.3f)\n",
      w.bottom_width_mm, w.height_mm, w.top_width_mm, w.rake_deg, w.bow_mm, w.bottom_left_m.x,
      w.bottom_left_m.y, w.bottom_left_m.z);
  EXPECT_NEAR(w.bottom_width_mm, glass.bottom_width_mm, 1.0);
  EXPECT_NEAR(w.top_width_mm, glass.top_width_mm, 1.0);
  EXPECT_NEAR(w.height_mm, glass.height_mm, 1.0);
  EXPECT_NEAR(w.rake_deg, glass.rake_deg, 0.05);
  EXPECT_LT(w.bow_mm, 0.5);
  EXPECT_LT(glm::length(w.bottom_left_m - glass.bottom_left_m), 0.002);
  EXPECT_EQ(cabin.triangles(), 0u);  // the windshield is the simulated glass's to draw
}

TEST(GltfModelTest, A200kTriangleModelReadsInUnderASecond) {
  VehicleModel big;
  // Rounded boxes finely cut until the model holds 200k triangles.
  for (int i = 0; big.triangles() < 200'000; ++i)
    add_rounded_box(big.mesh, {0.1f * i, -0.9f, 0.0f}, {0.1f * i + 4.0f, 0.9f, 1.4f}, 0.3f,
                    {material::kBody}, {1, 1}, 24);
  big.fixed_index_count = static_cast<std::uint32_t>(big.mesh.indices.size());
  const std::string glb = write_glb(big);
  const auto t0 = std::chrono::steady_clock::now();
  const VehicleModel read = read_gltf(glb, ModelKind::kVehicle);
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("%zu triangles, %.1f MB: read in %.3f s\n", read.triangles(), glb.size() / 1e6, s);
  EXPECT_EQ(read.triangles(), big.triangles());
#if defined(NDEBUG) && !defined(__SANITIZE_ADDRESS__) && !defined(__SANITIZE_THREAD__)
  EXPECT_LT(s, 1.0);
#endif
}

}  // namespace
}  // namespace downpour::model
