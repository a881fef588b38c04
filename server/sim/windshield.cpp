#include "server/sim/windshield.hpp"

#include <cmath>

#include <glm/geometric.hpp>

namespace downpour::sim {

bool GlassConfig::contains(glm::dvec2 uv) const {
  if (uv.y < 0.0 || uv.y > height_mm) return false;
  const double inset = inset_mm(uv.y);
  return uv.x >= inset && uv.x <= bottom_width_mm - inset;
}

glm::dvec3 GlassConfig::u_axis() const { return {0.0, -1.0, 0.0}; }

glm::dvec3 GlassConfig::v_axis() const {
  const double rake = rake_deg * M_PI / 180.0;
  return {-std::sin(rake), 0.0, std::cos(rake)};
}

glm::dvec3 GlassConfig::normal() const { return glm::cross(v_axis(), u_axis()); }

glm::dvec3 GlassConfig::to_vehicle(glm::dvec2 uv) const {
  return bottom_left_m + (uv.x * 1e-3) * u_axis() + (uv.y * 1e-3) * v_axis();
}

}  // namespace downpour::sim
