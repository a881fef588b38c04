// The surface of the water on the windshield as the light meets it (beyond seed 000): each body of
// water a shape of its own, whose height over the glass the renderer evaluates where a ray crosses
// it, finer than any map. Small drops are spherical caps; bodies wider than the capillary length
// flatten under gravity and sag downhill into tears; running drops stretch along their run with a
// tail; trails are cylinders. Where the water is, for every view and for the wet fractions the
// frames report, is read from here. Glass space, millimetres; plain data, no GL.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include <glm/vec2.hpp>

#include "server/sim/windshield.hpp"

namespace downpour::sim {

class WorkerThread;

// One body of water, laid out as the renderer's texture buffer holds it (three RGBA texels; the
// GLSL side is glass_surface.glsl's Body). Its outline, in the frame of its axis: the points within
// side_mm across the axis and, along it, within front_mm beyond the end of its segment (the
// +axis end, half_length_mm from the centre) or back_mm beyond the start. Its height over a point
// a fraction rho of the way out from the segment to the outline: the profile of a spherical cap of
// radius side_mm, side (sqrt(1 / sin^2 theta - rho^2) - cot theta), theta the contact angle,
// stretched to the outline; where top_mm > 0 (flattened by gravity) never much more than top_mm,
// reached over about the capillary length from the edge. Outside the outline the surface goes on
// down at the contact angle. Where bodies overlap, the light meets the one that rises highest.
struct WaterBody {
  float u_mm = 0.0f, v_mm = 0.0f;       // centre
  float axis_u = 0.0f, axis_v = -1.0f;  // unit: down the glass, or along the run
  float side_mm = 0.0f, front_mm = 0.0f, back_mm = 0.0f, half_length_mm = 0.0f;
  float inv_sin2 = 1.0f, cot = 0.0f, tan = 1.0f;  // of the contact angle
  float top_mm = 0.0f;                            // 0: a cap however large
};
static_assert(sizeof(WaterBody) == 48, "three vec4s");

// The flat top's thickness of a wide body at this contact angle: 2 l_c sin(theta / 2).
double puddle_thickness_mm(double contact_angle_deg, double capillary_length_mm = 2.7);

// A drop of contact radius r: a spherical cap at this contact angle; with flatten, it flattens
// under gravity where wider than the capillary length allows.
WaterBody cap_body(glm::vec2 centre_mm, float radius_mm, double contact_angle_deg,
                   bool flatten = true, double capillary_length_mm = 2.7);
// A trail's piece: a cylinder of this cross-section half-width along `axis`, half_length each way.
WaterBody cylinder_body(glm::vec2 centre_mm, glm::vec2 axis, float half_width_mm,
                        float half_length_mm, double contact_angle_deg);
// The half-width of a cylinder of water at this contact angle holding mass_mg over length_mm.
double cylinder_half_width_mm(double mass_mg, double length_mm, double contact_angle_deg);

// The farthest a body's outline reaches from its centre (mm).
double body_reach_mm(const WaterBody& body);

// The bodies and a grid over the glass that lists, per cell, the bodies that reach it: what the
// renderer uploads and searches.
struct GlassWaterSurface {
  static constexpr double kCellMm = 4.0;
  static constexpr int kCountBits = 8;  // a cell lists at most 255 bodies
  std::vector<WaterBody> bodies;
  int cells_u = 0, cells_v = 0;
  // Per cell, rows from v = 0: (first entry << kCountBits) | count.
  std::vector<std::uint32_t> cells;
  std::vector<std::uint32_t> entries;  // body indices

  // The share of the glass's outline under water, from the cells' centres (index()). An unbiased
  // estimate: a drop smaller than a cell counts whole as often as its area is a cell's.
  double wet_fraction = 0.0;

  // Lists every body in the cells its outline may reach; counts the wet cells. With a helper that
  // is idle and at least kShareFrom bodies, the helper lists half of them (a busy one is not
  // waited for); the result is the same.
  static constexpr std::size_t kShareFrom = 2048;  // fewer are listed sooner than a helper wakes
  void index(const GlassConfig& glass, WorkerThread* helper = nullptr);

  // The height of a cap as high as the body that rises highest over glass point p, of those its
  // cell lists (the renderer's water_top): > 0 where p lies under water. Needs index().
  float top_height(glm::vec2 p) const;
};

// Round caps at the simulation's contact angle from metaballs of radius r (hand-made windshields
// in tests and tools).
std::shared_ptr<const GlassWaterSurface> surface_from_metaballs(
    const std::vector<Metaball>& metaballs, const GlassConfig& glass);

}  // namespace downpour::sim
