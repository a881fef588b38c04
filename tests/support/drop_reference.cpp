#include "tests/support/drop_reference.hpp"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

#include "server/render/cpu/display.hpp"

namespace downpour::testing {
namespace {

// Fresnel reflectance for unpolarised light from index n1 into n2, cos_i the incidence's cosine;
// 1 past the critical angle.
double fresnel(double n1, double n2, double cos_i) {
  const double sin_t = n1 / n2 * std::sqrt(std::max(1.0 - cos_i * cos_i, 0.0));
  if (sin_t >= 1.0) return 1.0;
  const double cos_t = std::sqrt(1.0 - sin_t * sin_t);
  const double rs = (n1 * cos_i - n2 * cos_t) / (n1 * cos_i + n2 * cos_t);
  const double rp = (n1 * cos_t - n2 * cos_i) / (n1 * cos_t + n2 * cos_i);
  return 0.5 * (rs * rs + rp * rp);
}

// Direction d (unit) across an interface of normal n (unit, on d's far side: dot(d, n) > 0) from
// index n1 into n2; false past the critical angle.
bool bend(const glm::dvec3& d, const glm::dvec3& n, double n1, double n2, glm::dvec3* out) {
  const double eta = n1 / n2, c = glm::dot(d, n);
  const double k = 1.0 - eta * eta * (1.0 - c * c);
  if (k < 0.0) return false;
  *out = glm::normalize(eta * d + (std::sqrt(k) - eta * c) * n);
  return true;
}

struct Tracer {
  const ReferenceGlass& glass;
  const ReferenceDrop& drop;
  const ReferenceEnvironment& env;
  glm::dvec3 cabin;
  double ior;
  glm::dvec3 normal;  // out of the car
  double sphere_r = 0.0;
  glm::dvec3 centre;  // the sphere's, glass frame (mm): u, v, out

  glm::dvec3 to_world(const glm::dvec3& g) const {
    return g.x * glass.u + g.y * glass.v + g.z * normal;
  }

  // What the eye sees along world direction d from the eye, crossing the glass at glass point
  // (mm) g; `wet` is set where the ray meets the drop.
  glm::dvec3 radiance(const glm::dvec3& d, const glm::dvec2& g, bool* wet) const {
    *wet = glm::length(g - drop.centre_mm) < drop.radius_mm;
    if (!*wet) return env.radiance(d);
    const glm::dvec3 dg(glm::dot(d, glass.u), glm::dot(d, glass.v), glm::dot(d, normal));
    glm::dvec3 w;
    bend(dg, {0.0, 0.0, 1.0}, 1.0, ior, &w);  // into the water (the glass only shifts it)
    glm::dvec3 p(g, 0.0);
    glm::dvec3 light(0.0), carried(1.0);
    for (int bounce = 0; bounce < 12; ++bounce) {
      // The next surface: the sphere from inside (its far root), or the glass below.
      const glm::dvec3 oc = p - centre;
      const double b = glm::dot(oc, w), c = glm::dot(oc, oc) - sphere_r * sphere_r;
      const double s_sphere = -b + std::sqrt(std::max(b * b - c, 0.0));
      const double s_glass = w.z < 0.0 ? -p.z / w.z : 1e30;
      if (s_glass < s_sphere) {
        // Down through the glass: out into the cabin, or trapped in the glass (parallel faces:
        // it leaves only if it would leave water into air at this angle).
        const double sin_air = ior * std::sqrt(std::max(1.0 - w.z * w.z, 0.0));
        if (sin_air < 1.0) light += carried * cabin;
        return light;
      }
      const glm::dvec3 x = p + s_sphere * w;
      const glm::dvec3 n = (x - centre) / sphere_r;
      const double f = fresnel(ior, 1.0, glm::dot(w, n));
      glm::dvec3 out;
      if (f < 1.0 && bend(w, n, ior, 1.0, &out))
        light += carried * (1.0 - f) * env.radiance(glm::normalize(to_world(out)));
      carried *= f;
      if (std::max({carried.x, carried.y, carried.z}) < 1e-4) return light;
      w = glm::reflect(w, n);
      p = x - n * 1e-9;
    }
    return light;
  }
};

}  // namespace

glm::dvec3 ReferenceEnvironment::radiance(const glm::dvec3& d) const {
  if (d.z >= 0.0) {
    glm::dvec3 sky = glm::mix(horizon, zenith, std::sqrt(d.z));
    if (glm::dot(d, sun_dir) > std::cos(sun_radius_rad)) sky += sun_radiance;
    return sky;
  }
  // The ground: squares on a plane ground_depth_m under the eye; towards the horizon, where
  // squares shrink below any pixel, their mean.
  const double t = ground_depth_m / -d.z;
  const double x = d.x * t / square_m, y = d.y * t / square_m;
  const bool light_square =
      (static_cast<long>(std::floor(x)) + static_cast<long>(std::floor(y))) % 2 == 0;
  const glm::dvec3 square = light_square ? ground_light : ground_dark;
  const double fade = std::clamp((-d.z - 0.02) / 0.1, 0.0, 1.0);
  return glm::mix(0.5 * (ground_light + ground_dark), square, fade);
}

ReferencePixels trace_drop(const ReferenceView& view, const ReferenceGlass& glass,
                           const ReferenceDrop& drop, const ReferenceEnvironment& env,
                           const glm::dvec3& cabin, double ior) {
  Tracer tracer{
      glass, drop,           env, cabin, ior, glm::normalize(glm::cross(glass.v, glass.u)),
      0.0,   glm::dvec3(0.0)};
  const double q = drop.contact_angle_deg * M_PI / 180.0;
  tracer.sphere_r = drop.radius_mm / std::sin(q);
  tracer.centre = glm::dvec3(drop.centre_mm, -tracer.sphere_r * std::cos(q));

  // The window: where the contact circle projects, and two pixels round it.
  const glm::dmat4 view_proj = glm::inverse(view.inv_view_proj);
  double x_lo = 1e9, x_hi = -1e9, y_lo = 1e9, y_hi = -1e9;
  for (int k = 0; k < 32; ++k) {
    const double a = 2.0 * M_PI * k / 32.0;
    const glm::dvec2 g = drop.centre_mm + drop.radius_mm * glm::dvec2(std::cos(a), std::sin(a));
    const glm::dvec3 world = glass.origin + (g.x * glass.u + g.y * glass.v) * 1e-3;
    const glm::dvec4 clip = view_proj * glm::dvec4(world, 1.0);
    const double x = (clip.x / clip.w * 0.5 + 0.5) * view.width;
    const double y = (0.5 - clip.y / clip.w * 0.5) * view.height;
    x_lo = std::min(x_lo, x), x_hi = std::max(x_hi, x), y_lo = std::min(y_lo, y),
    y_hi = std::max(y_hi, y);
  }
  ReferencePixels out;
  out.x0 = std::max(0, static_cast<int>(std::floor(x_lo)) - 2);
  out.y0 = std::max(0, static_cast<int>(std::floor(y_lo)) - 2);
  out.width = std::min(view.width, static_cast<int>(std::ceil(x_hi)) + 3) - out.x0;
  out.height = std::min(view.height, static_cast<int>(std::ceil(y_hi)) + 3) - out.y0;
  out.width = std::max(out.width, 0);
  out.height = std::max(out.height, 0);
  const std::size_t n = static_cast<std::size_t>(out.width) * out.height;
  out.luma.resize(n);
  out.coverage.resize(n);
  out.rgb.resize(3 * n);
  const int k = view.rays_per_axis;
  const glm::dvec3 normal = tracer.normal;
  for (int py = 0; py < out.height; ++py) {
    for (int px = 0; px < out.width; ++px) {
      glm::dvec3 sum(0.0);
      int wet = 0;
      for (int j = 0; j < k; ++j) {
        for (int i = 0; i < k; ++i) {
          // Stratified over the pixel (rows top-down in the image, clip y up).
          const double sx = out.x0 + px + (i + 0.5) / k, sy = out.y0 + py + (j + 0.5) / k;
          const glm::dvec4 far =
              view.inv_view_proj *
              glm::dvec4(sx / view.width * 2.0 - 1.0, 1.0 - sy / view.height * 2.0, 1e-6, 1.0);
          const glm::dvec3 d = glm::normalize(glm::dvec3(far) / far.w - view.eye);
          const double t = glm::dot(glass.origin - view.eye, normal) / glm::dot(d, normal);
          const glm::dvec3 hit = view.eye + t * d - glass.origin;
          const glm::dvec2 g = glm::dvec2(glm::dot(hit, glass.u), glm::dot(hit, glass.v)) * 1e3;
          bool is_wet = false;
          sum += tracer.radiance(d, g, &is_wet);
          wet += is_wet;
        }
      }
      const glm::vec3 shown = render::to_display(glm::vec3(sum / static_cast<double>(k * k)));
      const std::size_t at = static_cast<std::size_t>(py) * out.width + px;
      out.coverage[at] = static_cast<double>(wet) / (k * k);
      out.luma[at] = 255.0 * (0.2126 * shown.r + 0.7152 * shown.g + 0.0722 * shown.b);
      for (int c = 0; c < 3; ++c)
        out.rgb[3 * at + c] = static_cast<std::uint8_t>(std::lround(255.0 * shown[c]));
    }
  }
  return out;
}

}  // namespace downpour::testing
