#include "server/render/passes/vehicle_pass.hpp"

#include <glm/gtc/matrix_transform.hpp>

#include "server/render/light_set.hpp"
#include "server/render/vehicle_geometry.hpp"
#include "server/sim/pose.hpp"

namespace downpour::render {

VehiclePass::VehiclePass(SharedResources&)
    : program_("mesh.vert", "vehicle.frag"),
      u_model_(program_.uniform("u_model")),
      u_body_colour_(program_.uniform("u_body_colour")),
      u_lamps_(program_.uniform("u_lamps")),
      u_head_(program_.uniform("u_head")),
      hull_(build_car_hull()),
      upper_(build_car_upper()) {}

void VehiclePass::draw_car(const glm::mat4& model, const glm::vec3& colour,
                           const sim::VehicleLights& lights, bool flash_on, bool hull_only) {
  u_model_.set(model);
  u_body_colour_.set(colour);
  const bool heads =
      lights.headlights == sim::Headlights::kLow || lights.headlights == sim::Headlights::kHigh;
  const float flash = flash_on ? 1.0f : 0.0f;
  u_lamps_.set(glm::vec4(heads ? 1.0f : 0.0f, lights.brake ? 1.0f : 0.0f,
                         lights.left_indicator ? flash : 0.0f,
                         lights.right_indicator ? flash : 0.0f));
  u_head_.set(lights.headlights == sim::Headlights::kHigh ? 2.0f : heads ? 1.0f : 0.0f);
  hull_.draw();
  if (!hull_only) upper_.draw();
}

void VehiclePass::execute(const FrameContext& frame, const FrameResources&) {
  program_.use();
  // From the driver's eye (COCKPIT, and RAIN, which sees from it) only the hood shows.
  const bool cockpit =
      frame.spec.view == sim::View::kCockpit || frame.spec.view == sim::View::kRain;
  const bool flash_on = sim::indicator_lit(frame.scene.sim_time_s);
  const sim::Weather& weather = frame.scene.weather;
  draw_car(frame.vehicle_to_world, glm::vec3(0.42f, 0.05f, 0.04f),
           shown_lights(frame.scene.ego_lights, weather), flash_on, cockpit);
  const glm::mat4 view_proj = frame.camera.projection * frame.camera.view;
  static const glm::vec3 palette[] = {{0.75f, 0.75f, 0.78f}, {0.05f, 0.06f, 0.08f},
                                      {0.1f, 0.2f, 0.45f},   {0.55f, 0.55f, 0.5f},
                                      {0.35f, 0.02f, 0.02f}, {0.9f, 0.9f, 0.88f}};
  for (std::size_t i = 0; i < frame.scene.traffic.size(); ++i) {
    const sim::TrafficVehicle& other = frame.scene.traffic[i];
    // The car shape is 4.6 x 1.8 x 1.47 m from the rear axle; scale it to the reported size.
    const glm::vec3 scale(other.size_m.x / 4.6, other.size_m.y / 1.8, other.size_m.z / 1.47);
    const glm::mat4 model = glm::scale(glm::mat4(sim::vehicle_to_world(other.state)), scale);
    const glm::vec3 centre = glm::vec3(model * glm::vec4(1.35f, 0.0f, 0.7f, 1.0f));
    if (!box_visible(view_proj, centre - glm::vec3(4.0f), centre + glm::vec3(4.0f))) continue;
    const sim::VehicleLights lights = i < frame.scene.traffic_lights.size()
                                          ? frame.scene.traffic_lights[i]
                                          : sim::VehicleLights{};
    draw_car(model, palette[other.id % 6], shown_lights(lights, weather), flash_on, false);
  }
}

}  // namespace downpour::render
