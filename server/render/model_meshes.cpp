#include "server/render/model_meshes.hpp"

#include <cmath>

#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>

namespace downpour::render {

ModelMesh::ModelMesh(const model::VehicleModel& m)
    : mesh(m.mesh), fixed(m.fixed_index_count), bonnet(m.bonnet_index_count), wheels(m.wheels) {}

void ModelMesh::draw(const Uniform& u_model, const glm::mat4& model, double rolled_m,
                     bool bonnet_only) const {
  u_model.set(model);
  mesh.draw(0, bonnet_only ? bonnet : fixed);
  if (bonnet_only) return;
  for (const model::Wheel& w : wheels) {
    const double turns = rolled_m / (2.0 * glm::pi<double>() * w.radius_m);
    const auto angle = static_cast<float>(2.0 * glm::pi<double>() * (turns - std::floor(turns)));
    u_model.set(glm::translate(
        glm::rotate(glm::translate(model, w.centre), angle, glm::vec3(0.0f, 1.0f, 0.0f)),
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
