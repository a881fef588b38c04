#include "server/render/model_meshes.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>

#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "server/render/cpu/shader_interface.hpp"

namespace downpour::render {

namespace {

// The vertices each wheel's triangles use, [lowest, highest + 1), where no other part's triangle
// uses one in that range, the wheels' triangles follow the fixed parts' one after another, and
// there are at most kMaxWheels wheels; else none.
std::vector<glm::ivec2> wheel_vertex_ranges(const model::VehicleModel& m) {
  const std::vector<model::Wheel>& wheels = m.wheels;
  if (wheels.empty() || wheels.size() > static_cast<std::size_t>(ModelMesh::kMaxWheels)) return {};
  std::uint32_t next = m.fixed_index_count;
  for (const model::Wheel& w : wheels) {
    if (w.first_index != next) return {};
    next += w.index_count;
  }
  const std::vector<std::uint32_t>& indices = m.mesh.indices;
  std::vector<glm::ivec2> ranges;
  for (const model::Wheel& w : wheels) {
    std::uint32_t lo = UINT32_MAX, hi = 0;
    for (std::uint32_t k = w.first_index; k < w.first_index + w.index_count; ++k) {
      lo = std::min(lo, indices[k]);
      hi = std::max(hi, indices[k]);
    }
    if (lo > hi) lo = hi = 0;  // a wheel without triangles
    ranges.emplace_back(static_cast<int>(lo), static_cast<int>(hi) + 1);
  }
  // Every index of the mesh lies in the range of its own wheel or in none.
  for (std::size_t k = 0; k < indices.size(); ++k) {
    const auto v = static_cast<int>(indices[k]);
    for (std::size_t w = 0; w < wheels.size(); ++w) {
      const bool own =
          k >= wheels[w].first_index && k < wheels[w].first_index + wheels[w].index_count;
      if (!own && v >= ranges[w].x && v < ranges[w].y) return {};
    }
  }
  return ranges;
}

float wheel_angle(double rolled_m, const model::Wheel& w) {
  const double turns = rolled_m / (2.0 * glm::pi<double>() * w.radius_m);
  return static_cast<float>(2.0 * glm::pi<double>() * (turns - std::floor(turns)));
}

}  // namespace

ModelUniforms::ModelUniforms(const ShaderProgram& program)
    : model(program.uniform("u_model")),
      wheel_count(program.uniform("u_wheel_count")),
      wheel_vertices(program.uniform("u_wheel_vertices")),
      wheel_turn(program.uniform("u_wheel_turn")),
      textured(program.uniform("u_textured")) {}

namespace {
std::uint64_t next_mesh_serial() {
  static std::atomic<std::uint64_t> made{0};
  return ++made;
}
}  // namespace

ModelMesh::ModelMesh(const model::VehicleModel& m)
    : serial(next_mesh_serial()),
      mesh(m.mesh),
      fixed(m.fixed_index_count),
      bonnet(m.bonnet_index_count),
      wheels(m.wheels),
      wheel_vertices(wheel_vertex_ranges(m)) {
  if (m.textures.empty()) return;
  constexpr int side = model::kModelTextureSide;
  const auto layers = static_cast<GLsizei>(m.textures.size());
  GLuint id = 0;
  glCreateTextures(GL_TEXTURE_2D_ARRAY, 1, &id);
  textures = Texture(id);
  glTextureStorage3D(id, 10, GL_SRGB8_ALPHA8, side, side, layers);  // 512 down to 1
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  for (GLsizei l = 0; l < layers; ++l)
    glTextureSubImage3D(id, 0, 0, 0, l, side, side, 1, GL_RGBA, GL_UNSIGNED_BYTE,
                        m.textures[static_cast<std::size_t>(l)].rgba->data());
  glGenerateTextureMipmap(id);
  glTextureParameteri(id, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
  glTextureParameteri(id, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTextureParameteri(id, GL_TEXTURE_WRAP_S, GL_REPEAT);
  glTextureParameteri(id, GL_TEXTURE_WRAP_T, GL_REPEAT);
}

void ModelMesh::draw(const ModelUniforms& u, const glm::mat4& model, double rolled_m,
                     bool bonnet_only) const {
  u.model.set(model);
  u.textured.set(textures.id() != 0 ? 1.0f : 0.0f);
  if (textures.id() != 0) glBindTextureUnit(texture_unit::kModelTexture, textures.id());
  if (bonnet_only || wheels.empty()) {
    u.wheel_count.set(0);
    mesh.draw(0, bonnet_only ? bonnet : fixed);
    return;
  }
  if (!wheel_vertices.empty()) {
    // The wheels follow the fixed parts in the indices: one draw.
    std::array<glm::vec4, kMaxWheels> turn;
    for (std::size_t k = 0; k < wheels.size(); ++k) {
      const float a = wheel_angle(rolled_m, wheels[k]);
      turn[k] = glm::vec4(wheels[k].centre.x, wheels[k].centre.z, std::cos(a), std::sin(a));
    }
    const auto n = static_cast<int>(wheels.size());
    u.wheel_count.set(n);
    u.wheel_vertices.set(wheel_vertices.data(), n);
    u.wheel_turn.set(turn.data(), n);
    const model::Wheel& last = wheels.back();
    mesh.draw(0, last.first_index + last.index_count);
    return;
  }
  u.wheel_count.set(0);
  mesh.draw(0, fixed);
  for (const model::Wheel& w : wheels) {
    u.model.set(glm::translate(glm::rotate(glm::translate(model, w.centre),
                                           wheel_angle(rolled_m, w), glm::vec3(0.0f, 1.0f, 0.0f)),
                               -w.centre));
    mesh.draw(w.first_index, w.index_count);
  }
}

const ModelMesh& ModelMeshes::get(const std::shared_ptr<const model::VehicleModel>& m) {
  Entry& e = entries_[m.get()];
  // A new model, or another at the address of one let go of since.
  if (!e.mesh || e.model.expired()) {
    e.model = m;
    e.mesh = std::make_unique<ModelMesh>(*m);
  }
  return *e.mesh;
}

void ModelMeshes::prune() {
  std::erase_if(entries_, [](const auto& e) { return e.second.model.expired(); });
}

}  // namespace downpour::render
