#include "server/render/passes/street_light_pass.hpp"

#include <glm/geometric.hpp>

#include "server/render/vehicle_geometry.hpp"
#include "server/render/world.hpp"

namespace downpour::render {
namespace {

// A box of half sizes `half` along (along, across, up) about `centre`, in world coordinates.
void add_oriented_box(MeshData& m, const glm::vec3& centre, const glm::vec3& along,
                      const glm::vec3& half, float material) {
  MeshData local;
  local.add_box(-half, half, material);
  const glm::vec3 across(-along.y, along.x, 0.0f), up(0.0f, 0.0f, 1.0f);
  const auto base = static_cast<std::uint32_t>(m.vertices.size());
  for (const MeshVertex& v : local.vertices) {
    const glm::vec3 p = centre + along * v.position.x + across * v.position.y + up * v.position.z;
    const glm::vec3 n = along * v.normal.x + across * v.normal.y + up * v.normal.z;
    m.add_vertex(p, n, v.uv);
  }
  for (std::uint32_t i : local.indices) m.indices.push_back(base + i);
}

}  // namespace

std::vector<std::vector<MeshData>> build_street_light_chunks(
    const std::vector<sim::StreetLight>& lights) {
  constexpr std::size_t kPerChunk = 4;
  std::vector<std::vector<MeshData>> chunks;
  for (std::size_t first = 0; first < lights.size(); first += kPerChunk) {
    MeshData m;
    for (std::size_t i = first; i < std::min(lights.size(), first + kPerChunk); ++i) {
      const glm::vec3 lamp(lights[i].lamp_m), foot(lights[i].foot_m);
      glm::vec3 along(lamp.x - foot.x, lamp.y - foot.y, 0.0f);  // from the pole over the road
      const float reach = glm::length(along);
      along = reach > 1e-3f ? along / reach : glm::vec3(1.0f, 0.0f, 0.0f);
      const float top = lamp.z + 0.25f;
      // The pole, tapering in steps; the arm; the lamp's housing, its lens underneath.
      add_oriented_box(m, glm::vec3(foot.x, foot.y, 0.5f * (foot.z + top)), along,
                       glm::vec3(0.08f, 0.08f, 0.5f * (top - foot.z)), material::kBody);
      add_oriented_box(
          m, glm::vec3(foot) + along * (0.5f * reach) + glm::vec3(0.0f, 0.0f, top - foot.z - 0.04f),
          along, glm::vec3(0.5f * reach + 0.1f, 0.04f, 0.04f), material::kBody);
      add_oriented_box(m, lamp + glm::vec3(0.0f, 0.0f, 0.08f), along,
                       glm::vec3(0.35f, 0.16f, 0.07f), material::kBody);
      add_oriented_box(m, lamp, along, glm::vec3(0.3f, 0.13f, 0.012f), material::kStreetLamp);
    }
    chunks.push_back({std::move(m)});
  }
  return chunks;
}

StreetLightPass::StreetLightPass(SharedResources&)
    : program_("mesh.vert", "vehicle.frag"), u_head_(program_.uniform("u_head")) {
  program_.uniform("u_model").set(glm::mat4(1.0f));
  program_.uniform("u_body_colour").set(glm::vec3(0.3f, 0.31f, 0.32f));
  program_.uniform("u_lamps").set(glm::vec4(0.0f));
}

void StreetLightPass::execute(const FrameContext& frame, const FrameResources&) {
  program_.use();
  u_head_.set(sim::street_lights_on(frame.scene.weather) ? 1.0f : 0.0f);
  frame.world->street_light_poles.draw_visible(frame.camera.projection * frame.camera.view,
                                               frame.camera.position, frame.detail_distance_scale);
}

}  // namespace downpour::render
