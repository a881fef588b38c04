// The drops of a scene as they show in a frame (tests of the traced lenses): each drop's footprint,
// its pixels split into thirds up the glass, wet against dry.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/matrix.hpp>

#include "server/render/cpu/camera.hpp"
#include "server/render/cpu/glass_view.hpp"
#include "server/sim/glass_water_surface.hpp"
#include "server/sim/pose.hpp"
#include "server/sim/simulation.hpp"
#include "tests/support/png_io.hpp"

namespace downpour::testing {

inline double luma(const RgbaImage& image, int x, int y) {
  const std::uint8_t* p = &image.pixels[(static_cast<std::size_t>(y) * image.width + x) * 4];
  return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
}

// One drop's footprint in the frame: its pixels (those whose rays cross the glass within its
// outline) split into thirds up the glass, their mean luminance wet and dry.
struct Footprint {
  double radius_mm = 0.0;
  int top = 0, bottom = 0;
  double top_wet = 0.0, bottom_wet = 0.0, top_dry = 0.0, bottom_dry = 0.0;
  double lowest_dry = 255.0;  // the darkest pixel behind it, dry
  double highest_dry = 0.0;   // the brightest
  double change = 0.0;        // the mean of wet - dry over its pixels
  int pixels = 0;
  double min_elevation = 1.0;  // the lowest of its pixels' rays (sine)
  // What the drop adds to its bottom third over its top third.
  double inversion() const { return (bottom_wet - top_wet) - (bottom_dry - top_dry); }
};

// The drops of a scene: its water's bodies that are drops (not trails), at least min_radius.
inline std::vector<Footprint> footprints(const sim::SceneState& scene, const sim::ViewSpec& spec,
                                         const RgbaImage& wet, const RgbaImage& dry,
                                         double min_radius_mm) {
  const render::Camera camera = render::make_camera(spec, scene.vehicle);
  const render::GlassView view(camera, scene.glass, spec.height);
  const glm::mat4 inv_view_proj = glm::inverse(camera.projection * camera.view);
  // Every pixel's glass point (none where its ray misses the glass) and its ray's elevation.
  std::vector<glm::dvec2> glass(static_cast<std::size_t>(spec.width) * spec.height,
                                glm::dvec2(-1e9));
  std::vector<float> elevation(glass.size());
  for (int y = 0; y < spec.height; ++y) {
    for (int x = 0; x < spec.width; ++x) {
      const double sx = (x + 0.5) / spec.width * 2.0 - 1.0,
                   sy = 1.0 - (y + 0.5) / spec.height * 2.0;
      const std::size_t at = static_cast<std::size_t>(y) * spec.width + x;
      if (const auto g = view.hit(sx, sy); g && scene.glass.contains(*g)) glass[at] = *g;
      const glm::vec4 far = inv_view_proj * glm::vec4(sx, sy, 1e-6f, 1.0f);
      elevation[at] = glm::normalize(glm::vec3(far) / far.w - camera.position).z;
    }
  }
  std::vector<Footprint> out;
  for (const sim::WaterBody& b : scene.windshield.surface->bodies) {
    if (b.half_length_mm > 0.0f || b.side_mm < min_radius_mm) continue;
    const glm::dvec2 c(b.u_mm, b.v_mm);
    const double r = b.side_mm;
    // Its pixels: search round where its centre projects.
    const glm::dvec3 world = glm::dvec3(sim::vehicle_to_world(scene.vehicle) *
                                        glm::dvec4(scene.glass.to_vehicle(c), 1.0));
    const glm::vec4 clip = camera.projection * camera.view * glm::vec4(glm::vec3(world), 1.0f);
    const int cx = static_cast<int>((clip.x / clip.w * 0.5f + 0.5f) * spec.width);
    const int cy = static_cast<int>((0.5f - clip.y / clip.w * 0.5f) * spec.height);
    const int reach = static_cast<int>(r * view.pixels_per_mm() * 2.0) + 3;
    Footprint f;
    f.radius_mm = r;
    for (int y = std::max(cy - reach, 0); y <= std::min(cy + reach, spec.height - 1); ++y) {
      for (int x = std::max(cx - reach, 0); x <= std::min(cx + reach, spec.width - 1); ++x) {
        const std::size_t at = static_cast<std::size_t>(y) * spec.width + x;
        const glm::dvec2 d = glass[at] - c;
        if (glm::length(d) >= r) continue;
        f.lowest_dry = std::min(f.lowest_dry, luma(dry, x, y));
        f.highest_dry = std::max(f.highest_dry, luma(dry, x, y));
        f.change += luma(wet, x, y) - luma(dry, x, y);
        ++f.pixels;
        f.min_elevation = std::min(f.min_elevation, static_cast<double>(elevation[at]));
        if (d.y > r / 3.0) {
          ++f.top;
          f.top_wet += luma(wet, x, y);
          f.top_dry += luma(dry, x, y);
        } else if (d.y < -r / 3.0) {
          ++f.bottom;
          f.bottom_wet += luma(wet, x, y);
          f.bottom_dry += luma(dry, x, y);
        }
      }
    }
    if (f.top == 0 || f.bottom == 0) continue;
    f.change /= f.pixels;
    f.top_wet /= f.top, f.top_dry /= f.top, f.bottom_wet /= f.bottom, f.bottom_dry /= f.bottom;
    out.push_back(f);
  }
  return out;
}

}  // namespace downpour::testing
