// Vehicle and cabin models on the GPU: each model uploaded the first frame it is drawn (on the
// render thread; it was read and checked on a request's), kept while a scene holds it, and
// drawn as its fixed parts (or the bonnet alone, from the driver's seat) with each wheel turned
// by how far the vehicle has rolled.
//
// A model is one draw: model.vert turns each wheel's vertices about its axle. On llvmpipe a draw
// call costs about 11 us before its first triangle, and a car's body and four wheels drawn apart
// were five. A model whose wheels' vertices are not each a range of their own (a glTF file may
// share them), or that has more than model.vert's 16 wheels, is drawn a wheel at a time.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>

#include "server/model/vehicle_model.hpp"
#include "server/render/gl/gl_objects.hpp"

namespace downpour::render {

// model.vert's uniforms (mesh_vertex.glsl).
struct ModelUniforms {
  explicit ModelUniforms(const ShaderProgram& program);
  Uniform model, wheel_count, wheel_vertices, wheel_turn, textured;
};

// A model on the GPU: its mesh, and where its parts lie in it.
struct ModelMesh {
  static constexpr int kMaxWheels = 16;  // MAX_WHEELS in mesh_vertex.glsl

  explicit ModelMesh(const model::VehicleModel& m);
  // Which upload this is, never reused (an address may be another's later): what a picture of it
  // is kept under (CockpitPass).
  std::uint64_t serial = 0;
  Mesh mesh;
  std::uint32_t fixed = 0, bonnet = 0;
  std::vector<model::Wheel> wheels;
  // Each wheel's vertices, [x, y), where they are the wheel's alone; empty where not.
  std::vector<glm::ivec2> wheel_vertices;
  // Its base-colour textures as a layer each (none: 0), bound to model_tex for its draws.
  Texture textures;

  // Draws it with `model` as the uniform u_model: the fixed parts (or the bonnet alone), and each
  // wheel turned by rolled_m over its radius.
  void draw(const ModelUniforms& u, const glm::mat4& model, double rolled_m,
            bool bonnet_only) const;
};

class ModelMeshes {
 public:
  // The mesh of a model a scene holds (uploaded now if it is new). Render thread.
  const ModelMesh& get(const std::shared_ptr<const model::VehicleModel>& m);
  // Lets go of the meshes of models no scene holds any longer.
  void prune();

 private:
  struct Entry {
    std::weak_ptr<const model::VehicleModel> model;
    std::unique_ptr<ModelMesh> mesh;
  };
  std::map<const model::VehicleModel*, Entry> entries_;
};

}  // namespace downpour::render
