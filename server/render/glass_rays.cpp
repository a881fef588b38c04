#include "server/render/glass_rays.hpp"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

#include "server/render/camera.hpp"
#include "server/sim/pose.hpp"

namespace downpour::render {

GlassRays::GlassRays(const sim::ViewSpec& spec, const sim::GlassConfig& glass) : glass_(glass) {
  const sim::CameraPose pose = spec.camera ? *spec.camera : default_camera_pose(spec.view);
  origin_ = pose.position_m;
  axes_ = sim::rotation_matrix(pose.rotation);
  const double fov = spec.fov_deg > 0.0 ? spec.fov_deg : default_fov_deg(spec.view);
  tan_y_ = std::tan(fov * M_PI / 360.0);
  tan_x_ = tan_y_ * spec.width / std::max(spec.height, 1);
}

std::optional<glm::dvec2> GlassRays::hit(double x, double y) const {
  const glm::dvec3 dir = axes_[0] - (x * tan_x_) * axes_[1] + (y * tan_y_) * axes_[2];
  const glm::dvec3 normal = glass_.normal();
  const double facing = glm::dot(dir, normal);
  if (std::abs(facing) < 1e-9) return std::nullopt;
  const double t = glm::dot(glass_.bottom_left_m - origin_, normal) / facing;
  if (t <= 0.0) return std::nullopt;
  const glm::dvec3 p = origin_ + t * dir - glass_.bottom_left_m;
  return glm::dvec2(glm::dot(p, glass_.u_axis()), glm::dot(p, glass_.v_axis())) * 1e3;
}

}  // namespace downpour::render
