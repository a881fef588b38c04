#include "server/render/passes/vehicle_pass.hpp"

#include <algorithm>

#include <glm/gtc/matrix_transform.hpp>

#include "server/model/default_models.hpp"
#include "server/render/cpu/light_set.hpp"
#include "server/sim/pose.hpp"
#include "server/sim/vehicle_class.hpp"

namespace downpour::render {

VehiclePass::Build::Build(const std::vector<std::string>& defines)
    : program("model.vert", "vehicle.frag", defines),
      uniforms(program),
      u_body_colour(program.uniform("u_body_colour")),
      u_lamps(program.uniform("u_lamps")),
      u_head(program.uniform("u_head")),
      u_wet(program.uniform("u_wet")) {}

VehiclePass::VehiclePass(SharedResources&) : builds_{Build(kLampBuilds[0]), Build(kLampBuilds[1])} {
  for (const sim::VehicleClass c : {sim::VehicleClass::kCar, sim::VehicleClass::kTruck,
                                    sim::VehicleClass::kBus, sim::VehicleClass::kMotorbike}) {
    near_.emplace_back(model::default_vehicle(c, model::Detail::kFull));
    far_.emplace_back(model::default_vehicle(c, model::Detail::kFar));
  }
}

void VehiclePass::prepare(const glm::vec3& colour, const sim::VehicleLights& lights, bool flash_on,
                          float body_wet) {
  build_->u_body_colour.set(colour);
  build_->u_wet.set(body_wet);
  const bool heads =
      lights.headlights == sim::Headlights::kLow || lights.headlights == sim::Headlights::kHigh;
  const float flash = flash_on ? 1.0f : 0.0f;
  build_->u_lamps.set(glm::vec4(heads ? 1.0f : 0.0f, lights.brake ? 1.0f : 0.0f,
                                lights.left_indicator ? flash : 0.0f,
                                lights.right_indicator ? flash : 0.0f));
  build_->u_head.set(lights.headlights == sim::Headlights::kHigh ? 2.0f : heads ? 1.0f : 0.0f);
}

void VehiclePass::execute(const FrameContext& frame, const FrameResources&) {
  build_ = &builds_[lamps_build(frame)];
  build_->program.use();
  // From the driver's eye (COCKPIT, and RAIN, which sees from it) only the hood shows.
  const bool cockpit =
      frame.spec.view == sim::View::kCockpit || frame.spec.view == sim::View::kRain;
  const bool flash_on = sim::indicator_lit(frame.scene.sim_time_s);
  const sim::Weather& weather = frame.scene.weather;
  // Seen from outside, at the session's size (from the driver's seat, as the model was made).
  named_.prune();
  const sim::ModelPtr& ego_model = frame.scene.ego.body_model;
  const glm::vec3 made = ego_model ? ego_model->size() : glm::vec3(sim::EgoGeometry{}.size_m);
  const glm::vec3 ego_scale = cockpit ? glm::vec3(1.0f) : glm::vec3(frame.scene.ego.size_m) / made;
  prepare(glm::vec3(0.42f, 0.05f, 0.04f), shown_lights(frame.scene.ego_lights, weather), flash_on,
          frame.scene.ego_body_wet);
  const auto car = static_cast<std::size_t>(sim::VehicleClass::kCar);
  const ModelMesh* ego = ego_model ? &named_.get(ego_model) : &near_[car];
  // From the seat, the body as marked for the session's glass and eye (where they differ).
  if (cockpit && frame.scene.ego.bonnet_model) ego = &named_.get(frame.scene.ego.bonnet_model);
  ego->draw(build_->uniforms, glm::scale(frame.vehicle_to_world, ego_scale),
            frame.scene.ego_rolled_m, cockpit);
  // A vehicle under 40 pixels tall is drawn from its model for the distance.
  const float pixels_per_radian = 0.5f * static_cast<float>(frame.spec.height) /
                                  static_cast<float>(frame.camera.tan_half_fov_y);
  const glm::mat4 view_proj = frame.camera.projection * frame.camera.view;
  static const glm::vec3 palette[] = {{0.75f, 0.75f, 0.78f}, {0.05f, 0.06f, 0.08f},
                                      {0.1f, 0.2f, 0.45f},   {0.55f, 0.55f, 0.5f},
                                      {0.35f, 0.02f, 0.02f}, {0.9f, 0.9f, 0.88f}};
  for (std::size_t i = 0; i < frame.scene.traffic.size(); ++i) {
    const sim::TrafficVehicle& other = frame.scene.traffic[i];
    // The class's shape at its usual size, scaled to the reported one.
    const sim::VehicleLayout& layout = sim::vehicle_layout(other.vehicle_class);
    const glm::vec3 scale = other.model ? glm::vec3(other.size_m) / other.model->size()
                                        : glm::vec3(sim::layout_scale(other));
    const glm::mat4 model = glm::scale(glm::mat4(sim::vehicle_to_world(other.state)), scale);
    const glm::vec3 centre =
        glm::vec3(model * glm::vec4(glm::vec3(layout.rear_m + 0.5 * layout.size_m.x, 0.0,
                                              0.5 * layout.size_m.z),
                                    1.0f));
    const float reach = 0.6f * static_cast<float>(std::max(other.size_m.x, other.size_m.z));
    if (!box_visible(view_proj, centre - glm::vec3(reach), centre + glm::vec3(reach))) continue;
    const sim::VehicleLights lights = i < frame.scene.traffic_lights.size()
                                          ? frame.scene.traffic_lights[i]
                                          : sim::VehicleLights{};
    const float body_wet =
        i < frame.scene.traffic_body_wet.size() ? frame.scene.traffic_body_wet[i] : 0.0f;
    prepare(palette[other.id % 6], shown_lights(lights, weather), flash_on, body_wet);
    const double rolled =
        i < frame.scene.traffic_rolled_m.size() ? frame.scene.traffic_rolled_m[i] : 0.0;
    const float distance = glm::length(centre - frame.camera.position);
    const bool small =
        static_cast<float>(other.size_m.z) * pixels_per_radian < 40.0f * std::max(distance, 0.1f);
    const auto c = static_cast<std::size_t>(other.vehicle_class);
    const ModelMesh& shape = other.model ? named_.get(other.model) : small ? far_[c] : near_[c];
    shape.draw(build_->uniforms, model, rolled, false);
  }
}

}  // namespace downpour::render
