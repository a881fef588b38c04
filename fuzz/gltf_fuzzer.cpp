// Fuzz target: a vehicle or cabin model's file (glTF 2.0, binary or JSON) -> read_gltf, the reader
// sessions' models go through (model/gltf_model.hpp), tinygltf's parser included. The first byte
// picks the kind. A model read must hold what the renderer assumes: indices within its vertices,
// finite positions, wheels' ranges within its indices; written out and read again, it must give
// the same triangles; its textures are whole layers that its vertices name. Nothing may crash, leak
// or hit undefined behaviour.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

#include "server/model/default_models.hpp"
#include "server/model/gltf_model.hpp"

namespace {

using namespace downpour::model;

void require(bool ok) {
  if (!ok) std::abort();  // an invariant of a model read broke: a finding
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const ModelKind kind = data[0] % 2 == 0 ? ModelKind::kVehicle : ModelKind::kCabin;
  const std::string_view bytes(reinterpret_cast<const char*>(data + 1), size - 1);
  ModelLimits limits;
  limits.max_bytes = 1u << 20;
  limits.max_triangles = 20'000;
  limits.max_node_visits = 4096;
  limits.max_image_side = 256;
  limits.max_image_pixels = 1u << 18;
  VehicleModel m;
  try {
    m = read_gltf(bytes, kind, limits);
  } catch (const ModelError&) {
    return 0;  // refused, with a reason: fine
  }
  const std::size_t n = m.mesh.vertices.size();
  require(m.mesh.indices.size() % 3 == 0);
  require(m.triangles() <= limits.max_triangles);
  for (std::uint32_t i : m.mesh.indices) require(i < n);
  for (const auto& v : m.mesh.vertices)
    require(std::isfinite(v.position.x) && std::isfinite(v.position.y) &&
            std::isfinite(v.position.z) && std::isfinite(v.normal.x));
  require(m.fixed_index_count <= m.mesh.indices.size());
  // Textures: a layer each of the set size, every vertex reading one of them or none.
  require(m.mesh.texcoords.empty() == m.textures.empty());
  require(m.mesh.texcoords.empty() || m.mesh.texcoords.size() == n);
  for (const ModelTexture& t : m.textures)
    require(t.rgba &&
            t.rgba->size() == static_cast<std::size_t>(kModelTextureSide) * kModelTextureSide * 4);
  for (const auto& t : m.mesh.texcoords)
    require(t.layer == -1.0f ||
            (t.layer >= 0.0f && t.layer < static_cast<float>(m.textures.size()) &&
             std::isfinite(t.uv.x) && std::isfinite(t.uv.y)));
  for (const Wheel& w : m.wheels) {
    require(w.first_index + w.index_count <= m.mesh.indices.size());
    require(std::isfinite(w.radius_m) && w.radius_m > 0.0f);
  }
  if (m.triangles() == 0) return 0;  // a cabin of its windshield alone
  const VehicleModel again = read_gltf(write_glb(m), kind, limits);
  require(again.triangles() == m.triangles());
  require(again.wheels.size() == m.wheels.size());
  if (kind == ModelKind::kVehicle) mark_bonnet(m);
  require(m.bonnet_index_count <= m.fixed_index_count);
  return 0;
}
