#include "server/render/frame_block.hpp"

#include <cmath>
#include <cstddef>

#include <glm/geometric.hpp>
#include <glm/matrix.hpp>

#include "server/render/cpu/shader_interface.hpp"
#include "server/sim/pose.hpp"

namespace downpour::render {

Mirror mirror_in(const glm::dvec4& plane) {
  const glm::dvec3 n(plane);
  Mirror m;
  m.plane = glm::vec4(plane);
  glm::dmat4 r(1.0);
  for (int c = 0; c < 3; ++c) {
    for (int row = 0; row < 3; ++row) r[c][row] -= 2.0 * n[row] * n[c];
  }
  for (int row = 0; row < 3; ++row) r[3][row] = -2.0 * plane.w * n[row];
  m.matrix = glm::mat4(r);
  return m;
}

Mirror mirror_under(const sim::RoadNetwork& roads, const sim::VehicleState& vehicle) {
  const glm::dvec2 xy(vehicle.position_m);
  const sim::RoadPlace p = roads.project(xy, 50.0);
  const sim::TrackFrame f = roads.frame(p.road, p.s);
  const glm::dvec3 along =
      glm::normalize(glm::dvec3(std::cos(f.heading_rad), std::sin(f.heading_rad), f.grade));
  glm::dvec3 n = glm::normalize(glm::cross(along, glm::dvec3(f.left, 0.0)));
  if (n.z < 0.0) n = -n;
  const glm::dvec3 point(xy, roads.surface_height(p));
  return mirror_in(glm::dvec4(n, -glm::dot(n, point)));
}

bool road_reflects(const FrameContext& f) {
  if (const sim::RoadWaterImage* image = f.scene.road_water.get())
    return image->max_standing_mm > 0.03f;
  return f.atmosphere.wetness > 0.3f;
}

WaterBlock water_block(const FrameContext& f, const Mirror& mirror, bool reflection) {
  WaterBlock w;
  w.mirror = mirror;
  w.road_water.w = reflection ? 1.0f : 0.0f;
  if (const sim::RoadWaterImage* image = f.scene.road_water.get(); image && image->complete()) {
    w.road_water.x = static_cast<float>(image->levels);
    w.road_water.y = static_cast<float>(image->cells) / 4.0f;
    for (int l = 0; l < image->levels; ++l) {
      const double cell = image->level_cell_m(l);
      w.road_water_rings[l] =
          glm::vec4(static_cast<float>(image->origins[l].x * cell),
                    static_cast<float>(image->origins[l].y * cell),
                    static_cast<float>(1.0 / (image->cells * cell)), static_cast<float>(cell));
      w.road_water_reach[l] = static_cast<float>(image->reach_m(l));
    }
    w.road_water_state = glm::vec4(static_cast<float>(image->capacity_mm), image->mean_water_mm,
                                   image->mean_standing_mm, 1.0f);
  }
  return w;
}

namespace {

FrameBlock make_block(const FrameContext& f, const WaterBlock& water, const LampFields& lamps) {
  FrameBlock b;
  b.view_proj = f.camera.projection * f.camera.view;
  b.inv_view_proj = glm::inverse(b.view_proj);
  b.camera_pos = glm::vec4(f.camera.position, 1.0f);
  b.sun_dir = glm::vec4(f.atmosphere.sun_direction, 0.0f);
  b.sun_radiance = glm::vec4(f.atmosphere.sun_radiance, 0.0f);
  b.sky_zenith = glm::vec4(f.atmosphere.sky_zenith, 0.0f);
  b.sky_horizon = glm::vec4(f.atmosphere.sky_horizon, 0.0f);
  b.ambient = glm::vec4(f.atmosphere.ambient, 0.0f);
  b.fog = glm::vec4(f.atmosphere.fog_colour, f.atmosphere.fog_density);
  b.time_s = static_cast<float>(f.scene.sim_time_s);
  b.overcast = f.atmosphere.overcast;
  b.wetness = f.atmosphere.wetness;
  b.rain_rate_mm_h = static_cast<float>(f.scene.weather.rain_rate_mm_h);
  b.wind = glm::vec4(glm::vec3(sim::wind_velocity(f.scene.weather)), 0.0f);
  // (In the reflection's own frame, view_proj is already mirrored: the road reads these only in
  // the view's.)
  b.mirror_view_proj = b.view_proj * water.mirror.matrix;
  b.clip_plane = water.clip_plane;
  b.road_water = water.road_water;
  b.road_water_rings = water.road_water_rings;
  b.road_water_reach = water.road_water_reach;
  b.road_water_state = water.road_water_state;
  b.lamp_map = lamps.params;
  b.lamp_rings = lamps.rings;
  return b;
}

}  // namespace

FrameBlockBuffer::FrameBlockBuffer() : view_(std::make_unique<FrameBlock>()) {
  ubo_ = make_buffer();
  glNamedBufferStorage(ubo_.id(), sizeof(FrameBlock), nullptr, GL_DYNAMIC_STORAGE_BIT);
  glBindBufferBase(GL_UNIFORM_BUFFER, kFrameBlockBinding, ubo_.id());
}

void FrameBlockBuffer::upload_view(const FrameContext& f, const WaterBlock& water) {
  *view_ = make_block(f, water, lamps_);
  view_water_ = water;
  restore_view();
}

void FrameBlockBuffer::upload(const FrameContext& f, const WaterBlock& water) {
  const FrameBlock b = make_block(f, water, lamps_);
  glNamedBufferSubData(ubo_.id(), 0, sizeof(b), &b);
}

void FrameBlockBuffer::restore_view() {
  glNamedBufferSubData(ubo_.id(), 0, sizeof(FrameBlock), view_.get());
}

void FrameBlockBuffer::set_clip_plane(const glm::vec4& plane) {
  glNamedBufferSubData(ubo_.id(), offsetof(FrameBlock, clip_plane), sizeof(plane), &plane);
}

}  // namespace downpour::render
