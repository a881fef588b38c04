#include "server/sim/drop_physics.hpp"

#include <algorithm>
#include <cmath>

namespace downpour::sim {
namespace {

// A spherical cap of contact radius a and contact angle q holds pi a^3 t (3 + t^2) / 6 of water,
// t = tan(q / 2); seen along the glass it is a circular segment of the sphere (radius a / sin q)
// over the angle 2q.
const double kCapVolumePerCubedRadius = [] {
  const double t = std::tan(0.5 * kContactAngleDeg * M_PI / 180.0);
  return M_PI * t * (3.0 + t * t) / 6.0;
}();
const double kCapFrontalAreaPerSquaredRadius = [] {
  const double q = kContactAngleDeg * M_PI / 180.0, sphere = 1.0 / std::sin(q);
  return 0.5 * sphere * sphere * (2.0 * q - std::sin(2.0 * q));
}();

}  // namespace

double drop_radius_mm(double mass_mg) {
  return std::cbrt(std::max(mass_mg, 0.0) / kCapVolumePerCubedRadius);
}
double drop_mass_mg(double radius_mm) {
  return kCapVolumePerCubedRadius * radius_mm * radius_mm * radius_mm;
}
double drop_frontal_area_mm2(double radius_mm) {
  return kCapFrontalAreaPerSquaredRadius * radius_mm * radius_mm;
}
double terminal_speed_mps(double d_mm) {
  return std::max(0.0, 9.65 - 10.3 * std::exp(-0.6 * d_mm));
}

}  // namespace downpour::sim
