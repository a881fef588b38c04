#include "server/render/cpu/glass_view.hpp"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

namespace downpour::render {

GlassView::GlassView(const Camera& camera, const sim::GlassConfig& glass, int image_height,
                     int min_layer_scale, double layer_widening)
    : glass_(glass),
      origin_(camera.position_vehicle),
      axes_(camera.axes_vehicle),
      tan_x_(camera.tan_half_fov_x),
      tan_y_(camera.tan_half_fov_y),
      near_m_(camera.near_m),
      min_layer_scale_(min_layer_scale),
      layer_widening_(std::max(layer_widening, 1.0)),
      pinhole_(camera.aperture_mm <= 0.0) {
  const glm::dvec3 n = glass_.normal();
  const double facing = glm::dot(axes_[0], n);
  const double gap = glm::dot(glass_.bottom_left_m - origin_, n);
  if (facing > 1e-6 && gap > 0.0) {
    distance_m_ = gap / facing;
    const double focal_px = 0.5 * image_height / std::max(tan_y_, 1e-9);
    pixels_per_mm_ = focal_px / (distance_m_ * 1e3);
    blur_mm_ = camera.aperture_mm * std::abs(1.0 - distance_m_ / std::max(camera.focus_m, 1e-3));
  }
}

std::optional<glm::dvec2> GlassView::hit(double x, double y) const {
  const glm::dvec3 dir = axes_[0] - (x * tan_x_) * axes_[1] + (y * tan_y_) * axes_[2];
  const glm::dvec3 normal = glass_.normal();
  const double facing = glm::dot(dir, normal);
  if (std::abs(facing) < 1e-9) return std::nullopt;
  const double t = glm::dot(glass_.bottom_left_m - origin_, normal) / facing;
  if (t <= 0.0) return std::nullopt;
  const glm::dvec3 p = origin_ + t * dir - glass_.bottom_left_m;
  return glm::dvec2(glm::dot(p, glass_.u_axis()), glm::dot(p, glass_.v_axis())) * 1e3;
}

glm::vec3 GlassView::depth_over_image() const {
  // A point at image (x, y) and view distance t is origin + t (f - x tan_x l + y tan_y u); on the
  // plane n . (P - b) = 0 where 1 / t = (n.f - x tan_x n.l + y tan_y n.u) / n.(b - origin).
  const glm::dvec3 n = glass_.normal();
  const double gap = glm::dot(glass_.bottom_left_m - origin_, n);
  if (std::abs(gap) < 1e-9) return glm::vec3(0.0f);
  const double nf = glm::dot(n, axes_[0]), nl = glm::dot(n, axes_[1]), nu = glm::dot(n, axes_[2]);
  const double ax = -tan_x_ * nl / gap, ay = tan_y_ * nu / gap, c = nf / gap;
  // x = 2u - 1, y = 2v - 1; depth = near / t.
  return glm::vec3(near_m_ * 2.0 * ax, near_m_ * 2.0 * ay, near_m_ * (c - ax - ay));
}

glm::vec4 GlassView::screen_axes() const {
  auto on_screen = [&](const glm::dvec3& d) {
    const glm::dvec2 s(-glm::dot(d, axes_[1]), glm::dot(d, axes_[2]));
    const double len = glm::length(s);
    return len > 1e-9 ? s / len : glm::dvec2(0.0);
  };
  return glm::vec4(glm::vec2(on_screen(glass_.u_axis())), glm::vec2(on_screen(glass_.v_axis())));
}

int GlassView::layer_scale() const {
  if (pinhole_) return 1;
  return std::clamp(static_cast<int>(std::lround(blur_px())), std::clamp(min_layer_scale_, 1, 4),
                    4);
}

glm::ivec2 GlassView::layer_size(int width, int height) const {
  const int scale = layer_scale();
  const bool widened = !pinhole_ && std::lround(blur_px()) >= 2;
  const double across = widened ? scale * layer_widening_ : scale;
  return {std::max(1, static_cast<int>(std::ceil(width / across - 1e-9))),
          std::max(1, (height + scale - 1) / scale)};
}

}  // namespace downpour::render
