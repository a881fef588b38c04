#include "server/render/cpu/sky_scattering.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <glm/exponential.hpp>
#include <glm/geometric.hpp>

namespace downpour::render {

namespace {

// The distance along a ray from p (relative to the Earth's centre) in direction d to the sphere
// of radius r, from inside it.
double to_sphere(const glm::dvec3& p, const glm::dvec3& d, double r) {
  const double b = glm::dot(p, d);
  const double c = glm::dot(p, p) - r * r;
  return -b + std::sqrt(std::max(b * b - c, 0.0));
}

// Whether the ray hits the Earth (its shadow: no sunlight reaches p along d).
bool hits_earth(const glm::dvec3& p, const glm::dvec3& d, double r) {
  const double b = glm::dot(p, d);
  if (b > 0.0) return false;
  return glm::dot(p, p) - b * b < r * r;
}

// The optical depth of each kind of extinction at height h (m): Rayleigh, Mie, ozone.
struct Densities {
  double rayleigh, mie, ozone;
};
Densities densities(double h, const SkyScatteringConfig& c) {
  return {std::exp(-h / c.rayleigh_height_m), std::exp(-h / c.mie_height_m),
          std::max(0.0, 1.0 - std::abs(h - 25e3) / 15e3)};
}

glm::dvec3 extinction(const Densities& d, const SkyScatteringConfig& c) {
  return c.rayleigh_per_m * d.rayleigh + glm::dvec3(c.mie_per_m / c.mie_albedo * d.mie) +
         c.ozone_per_m * d.ozone;
}

}  // namespace

glm::dvec3 clear_sky_radiance(double sun_altitude_deg, double view_elevation_rad,
                              double azimuth_from_sun_rad, const SkyScatteringConfig& c) {
  const double alt = sun_altitude_deg * std::numbers::pi / 180.0;
  const glm::dvec3 sun(std::cos(alt), 0.0, std::sin(alt));
  const glm::dvec3 view(std::cos(view_elevation_rad) * std::cos(azimuth_from_sun_rad),
                        std::cos(view_elevation_rad) * std::sin(azimuth_from_sun_rad),
                        std::sin(view_elevation_rad));
  const glm::dvec3 eye(0.0, 0.0, c.earth_radius_m + 2.0);
  const double length = to_sphere(eye, view, c.atmosphere_radius_m);
  const double mu = glm::dot(view, sun);
  const double rayleigh_phase = 3.0 / (16.0 * std::numbers::pi) * (1.0 + mu * mu);
  const double g = c.mie_g;
  const double mie_phase = 3.0 / (8.0 * std::numbers::pi) * ((1.0 - g * g) * (1.0 + mu * mu)) /
                           ((2.0 + g * g) * std::pow(1.0 + g * g - 2.0 * g * mu, 1.5));
  glm::dvec3 sum(0.0), depth_view(0.0);
  double t_prev = 0.0;
  const int n = c.view_samples;
  for (int i = 0; i < n; ++i) {
    // Samples closer together near the eye, where the air is densest.
    const double t0 = length * std::pow(static_cast<double>(i) / n, 2.0);
    const double t1 = length * std::pow(static_cast<double>(i + 1) / n, 2.0);
    const double ds = t1 - t0;
    const glm::dvec3 p = eye + view * (0.5 * (t0 + t1));
    const double h = glm::length(p) - c.earth_radius_m;
    const Densities here = densities(h, c);
    depth_view += extinction(here, c) * (0.5 * (t0 + t1) - t_prev);
    t_prev = 0.5 * (t0 + t1);
    if (hits_earth(p, sun, c.earth_radius_m)) {
      depth_view += extinction(here, c) * (t1 - t_prev);
      t_prev = t1;
      continue;
    }
    glm::dvec3 depth_sun(0.0);
    const double to_top = to_sphere(p, sun, c.atmosphere_radius_m);
    for (int k = 0; k < c.sun_samples; ++k) {
      const double s0 = to_top * std::pow(static_cast<double>(k) / c.sun_samples, 2.0);
      const double s1 = to_top * std::pow(static_cast<double>(k + 1) / c.sun_samples, 2.0);
      const glm::dvec3 q = p + sun * (0.5 * (s0 + s1));
      depth_sun += extinction(densities(glm::length(q) - c.earth_radius_m, c), c) * (s1 - s0);
    }
    const glm::dvec3 scattering = c.rayleigh_per_m * (here.rayleigh * rayleigh_phase) +
                                  glm::dvec3(c.mie_per_m * here.mie * mie_phase);
    sum += glm::exp(-(depth_view + depth_sun)) * scattering * ds;
    depth_view += extinction(here, c) * (t1 - t_prev);
    t_prev = t1;
  }
  return sum;
}

std::vector<glm::vec3> clear_sky_table(double sun_altitude_deg, const SkyScatteringConfig& c) {
  std::vector<glm::vec3> out(static_cast<std::size_t>(kSkyTableWidth) * kSkyTableHeight);
  for (int j = 0; j < kSkyTableHeight; ++j) {
    const double v = static_cast<double>(j) / (kSkyTableHeight - 1);
    // The lowest row a degree and a half up: single scattering along a ray that grazes the
    // ground runs through hundreds of kilometres of air and reddens it all, where the light
    // scattered more than once (not modelled) keeps the real horizon pale.
    const double elevation = std::asin(std::max(v * v, std::sin(1.5 * std::numbers::pi / 180.0)));
    for (int i = 0; i < kSkyTableWidth; ++i) {
      const double u = static_cast<double>(i) / (kSkyTableWidth - 1);
      const double azimuth = std::acos(std::clamp(1.0 - 2.0 * u, -1.0, 1.0));
      out[static_cast<std::size_t>(j) * kSkyTableWidth + i] =
          glm::vec3(clear_sky_radiance(sun_altitude_deg, elevation, azimuth, c));
    }
  }
  return out;
}

}  // namespace downpour::render
