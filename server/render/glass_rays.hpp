// Where a view's rays meet the windshield's plane: the CPU side of the COCKPIT camera and the glass
// (no GL), for the water maps' layout and the view's wet fraction.
#pragma once

#include <optional>

#include <glm/mat3x3.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "server/sim/types.hpp"
#include "server/sim/windshield.hpp"

namespace downpour::render {

class GlassRays {
 public:
  // The view's camera as make_camera places it (ViewSpec::camera, else the view's default pose).
  GlassRays(const sim::ViewSpec& spec, const sim::GlassConfig& glass);

  // The glass-space point (mm) where the ray through view point (x right, y up, both in [-1, 1]
  // across the image) meets the glass's plane in front of the camera; none if it does not.
  std::optional<glm::dvec2> hit(double x, double y) const;

 private:
  const sim::GlassConfig& glass_;
  glm::dvec3 origin_;  // vehicle frame, m
  glm::dmat3 axes_;    // columns: forward, left, up
  double tan_x_ = 0.0;
  double tan_y_ = 0.0;
};

}  // namespace downpour::render
