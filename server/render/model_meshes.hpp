// Vehicle and cabin models on the GPU: each model uploaded the first frame it is drawn (on the
// render thread; it was read and checked on a request's), kept while a scene holds it, and
// drawn as its parts: the fixed ones (or the bonnet alone, from the driver's seat) and each wheel
// turned by how far the vehicle has rolled.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <vector>

#include <glm/mat4x4.hpp>

#include "server/model/vehicle_model.hpp"
#include "server/render/gl/gl_objects.hpp"

namespace downpour::render {

// A model on the GPU: its mesh, and where its parts lie in it.
struct ModelMesh {
  explicit ModelMesh(const model::VehicleModel& m);
  Mesh mesh;
  std::uint32_t fixed = 0, bonnet = 0;
  std::vector<model::Wheel> wheels;

  // Draws it with `model` as the uniform u_model: the fixed parts (or the bonnet alone), then each
  // wheel turned by rolled_m over its radius.
  void draw(const Uniform& u_model, const glm::mat4& model, double rolled_m,
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
