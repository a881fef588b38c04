#include "server/rpc/models.hpp"

#include "server/model/default_models.hpp"
#include "server/rpc/validation.hpp"

namespace downpour::rpc {

namespace {

grpc::Status load(model::ModelLibrary& library, const std::string& name, model::ModelKind kind,
                  const std::string& field, sim::ModelPtr* out) {
  model::ModelLibrary::Refusal refusal;
  *out = library.load(name, kind, &refusal);
  if (*out) return grpc::Status::OK;
  const grpc::StatusCode code = refusal.failure == model::ModelLibrary::Failure::kNotFound
                                    ? grpc::StatusCode::NOT_FOUND
                                : refusal.failure == model::ModelLibrary::Failure::kNoDirectory
                                    ? grpc::StatusCode::FAILED_PRECONDITION
                                    : grpc::StatusCode::INVALID_ARGUMENT;
  return {code, field + ": " + refusal.message};
}

}  // namespace

grpc::Status to_traffic_models(model::ModelLibrary& library, const v1::Update& in,
                               const std::string& field, sim::Update* out) {
  if (!out->traffic) return grpc::Status::OK;
  for (int i = 0; i < in.traffic_size() && i < static_cast<int>(out->traffic->size()); ++i) {
    const std::string& name = in.traffic(i).model();
    if (name.empty()) continue;
    const std::string f = field + ".traffic[" + std::to_string(i) + "].model";
    sim::TrafficVehicle& v = (*out->traffic)[i];
    if (auto s = load(library, name, model::ModelKind::kVehicle, f, &v.model); !s.ok()) return s;
    // Without a size of its own, the vehicle is as large as its model.
    const v1::Vec3& size = in.traffic(i).size_m();
    if (size.x() <= 0.0 || size.y() <= 0.0 || size.z() <= 0.0)
      v.size_m = glm::dvec3(v.model->size());
  }
  return grpc::Status::OK;
}

namespace {

// The cabin model into config->ego, and the session's glass from it where the request gives none.
grpc::Status to_cabin_model(model::ModelLibrary& library, const v1::EgoVehicle& in,
                            const std::string& field, session::SessionConfig* config) {
  if (in.cabin_model().empty()) return grpc::Status::OK;
  const std::string f = field + ".cabin_model";
  if (auto s =
          load(library, in.cabin_model(), model::ModelKind::kCabin, f, &config->ego.cabin_model);
      !s.ok())
    return s;
  const auto& outline = config->ego.cabin_model->windshield;
  if (!outline) return grpc::Status::OK;  // the glass as given, or the default car's
  if (!in.has_windshield()) {
    config->glass = model::glass_of(*outline);
    if (auto s = check_glass(config->glass, f + " (its windshield)"); !s.ok()) return s;
  }
  // (Against its own glass, only a bow out of flat can disagree.)
  if (const auto why = model::glass_disagreement(*outline, config->glass))
    return {grpc::StatusCode::INVALID_ARGUMENT,
            f + ": " + *why + (in.has_windshield() ? " (" + field + ".windshield)" : "")};
  return grpc::Status::OK;
}

}  // namespace

grpc::Status to_ego_models(model::ModelLibrary& library, const v1::EgoVehicle& in,
                           const std::string& field, session::SessionConfig* config) {
  if (!in.body_model().empty()) {
    if (auto s = load(library, in.body_model(), model::ModelKind::kVehicle, field + ".body_model",
                      &config->ego.body_model);
        !s.ok())
      return s;
    // Without a size of its own, the car is as large as its model.
    if (in.size_m().x() == 0.0 && in.size_m().y() == 0.0 && in.size_m().z() == 0.0)
      config->ego.size_m = glm::dvec3(config->ego.body_model->size());
  }
  if (auto s = to_cabin_model(library, in, field, config); !s.ok()) return s;
  // The library marks a body's bonnet for the default glass and eye (what the driver sees past
  // the glass's foot); a session with another glass or eye gets a copy marked for its own.
  config->ego.bonnet_model =
      model::bonnet_for(config->ego.body_model, config->glass, config->ego.eye_m);
  return grpc::Status::OK;
}

}  // namespace downpour::rpc
