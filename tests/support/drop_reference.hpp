// An offline reference for the optics of drops on the windshield, on the CPU and written apart from
// the renderer's shaders: rays from a pinhole eye traced exactly through spherical caps of water
// on the glass's outer face. A ray crosses the glass (parallel faces: a shift, no turn) into the
// water, meets the cap (a sphere), where Fresnel (exact, unpolarised) splits it: the part that
// leaves (Snell) sees a distant environment; the part reflected inside goes on, to the cap again or
// down through the glass, into the cabin or, too oblique to leave the glass, trapped in it (dark).
// Each pixel is the mean of many rays over it, then the renderer's display transform.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace downpour::testing {

// Distant light by direction (world, z up), linear radiance: a sky gradient with a sun's disc
// above the horizon, a checkered ground below it (squares on a plane under the eye, fading to
// their mean towards the horizon, where they would be finer than any pixel).
struct ReferenceEnvironment {
  glm::dvec3 zenith{0.25, 0.42, 0.85};
  glm::dvec3 horizon{0.8, 0.85, 0.9};
  glm::dvec3 sun_dir{1.0, 0.0, 0.0};  // unit
  double sun_radius_rad = 0.035;
  glm::dvec3 sun_radiance{12.0, 11.0, 9.0};
  glm::dvec3 ground_light{0.35, 0.33, 0.3};
  glm::dvec3 ground_dark{0.05, 0.07, 0.04};
  double ground_depth_m = 1.2;  // the plane's depth under the eye
  double square_m = 1.0;

  glm::dvec3 radiance(const glm::dvec3& dir) const;
};

// One drop: a spherical cap on the glass, centre in glass space (mm), contact radius and angle.
struct ReferenceDrop {
  glm::dvec2 centre_mm{0.0};
  double radius_mm = 1.0;
  double contact_angle_deg = 40.0;
};

struct ReferenceGlass {
  glm::dvec3 origin;  // glass space (0, 0) on the outer face, world (m)
  glm::dvec3 u, v;    // unit axes, world; the normal out of the car is cross(v, u)
};

struct ReferenceView {
  glm::dvec3 eye;            // world
  glm::dmat4 inv_view_proj;  // clip to world (the renderer's camera)
  int width = 0, height = 0;
  int rays_per_axis = 12;  // per pixel
};

struct ReferencePixels {
  int x0 = 0, y0 = 0, width = 0, height = 0;  // the window of the image, rows top-down
  std::vector<double> luma;                   // display-encoded, 0-255
  std::vector<double> coverage;               // share of the pixel's rays that meet the drop
  std::vector<std::uint8_t> rgb;              // display-encoded
};

// The pixels around a drop (every pixel any of whose rays meets it, and a margin of two) as the
// eye sees it, over a background of the environment. The cabin's radiance is what a ray that
// leaves the glass inwards meets.
ReferencePixels trace_drop(const ReferenceView& view, const ReferenceGlass& glass,
                           const ReferenceDrop& drop, const ReferenceEnvironment& env,
                           const glm::dvec3& cabin, double water_ior = 1.333);

}  // namespace downpour::testing
