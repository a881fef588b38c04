// The windshield as the water simulation and the renderer both see it (seed 000, section 1):
// its geometry in glass space, the wipers, the water model's parameters with the paper's defaults,
// and what the renderer reads each frame. Plain data, no GL.
//
// Glass space: millimetres in the plane of the glass, u across from the bottom-left corner (the
// driver's left, vehicle +y) to the right, v up the glass from its bottom edge. The glass is a
// trapezoid: at height v its left edge is at inset(v) and its right edge at bottom_width -
// inset(v).
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

#include <glm/ext/vector_double2.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace downpour::sim {

struct GlassConfig {
  double bottom_width_mm = 1520.0;
  double top_width_mm = 1360.0;
  double height_mm = 762.0;  // along the glass, bottom edge to top edge
  double rake_deg = 60.0;    // from vertical: gravity along the glass is g * cos(rake)
  // The bottom-left corner in the vehicle frame (x forward from the rear axle, y left, z up), m.
  glm::dvec3 bottom_left_m{2.06, 0.76, 0.98};

  double inset_mm(double v_mm) const {
    return 0.5 * (bottom_width_mm - top_width_mm) * v_mm / height_mm;
  }
  bool contains(glm::dvec2 uv_mm) const;
  // Vehicle-frame point (m) of a glass-space point (mm), and the glass's unit axes and normal
  // (the normal points out of the car: forward and up).
  glm::dvec3 to_vehicle(glm::dvec2 uv_mm) const;
  glm::dvec3 u_axis() const;  // vehicle -y
  glm::dvec3 v_axis() const;  // up the glass: back and up
  glm::dvec3 normal() const;
};

// One wiper blade, in glass space. Its angle is the direction from the pivot along the arm,
// counter-clockwise from +u; at park it lies along park_deg, and a sweep turns it by sweep_deg
// in the direction `turn` (+1 counter-clockwise, -1 clockwise) and back.
struct BladeConfig {
  glm::dvec2 pivot_mm{0.0};  // may lie below the glass (under the cowl)
  double length_mm = 600.0;  // wiped length, measured from the pivot
  double width_mm = 14.0;    // the rectangle that pushes water
  double park_deg = 0.0;
  double sweep_deg = 90.0;
  double turn = 1.0;
};

struct WiperConfig {
  // Two blades in tandem as on a left-hand-drive car: pivots under the cowl just below the glass,
  // parked below its bottom edge with the tips to the right (so that parking pushes water off the
  // glass), sweeping counter-clockwise up until they lean a little towards the driver's side.
  std::array<BladeConfig, 2> blades{
      BladeConfig{{250.0, -40.0}, 720.0, 14.0, 2.0, 95.0, 1.0},
      BladeConfig{{900.0, -40.0}, 640.0, 14.0, 1.0, 95.0, 1.0},
  };
  double low_cycles_per_min = 45.0;   // FMVSS 104: at least 45 on one speed
  double high_cycles_per_min = 65.0;  // a typical fast setting
  // Intermittent and single wipes run at the low speed.
};

// The shapes the water takes as the light meets it (beyond seed 000: the physics of drops resting
// on glass; glass_water_surface.hpp).
struct WaterShapeConfig {
  double capillary_length_mm = 2.7;  // sqrt(sigma / (rho g)) for water
  // A resting drop sags downhill into a tear by its Bond number along the glass,
  // B = (r / l_c)^2 cos(rake) (at most 1): its downhill reach grows by tear_front B, its uphill
  // reach shrinks by tear_back B.
  double tear_front = 0.25;
  double tear_back = 0.15;
  // A running drop: a rounded front, a tail behind reaching run_back radii, a little narrower.
  double run_back = 1.6;
  double run_side = 0.85;
};

// The water model's parameters (seed 000, and what this project adds).
struct WaterConfig {
  double cell_mm = 2.0;             // mesh model cell
  double affinity_min = 0.3;        // per-cell random affinity in [min, 1]
  double critical_radius_mm = 2.2;  // a drop this big starts to flow under gravity alone
  double mobility_mm_s = 60.0;      // flow speed of a drop whose drive is twice its pinning
  double max_speed_mm_s = 400.0;
  double trail_fraction = 0.01;       // of a moving drop's mass left behind per cell moved
  int trail_spacing_cells = 3;        // left as one trail drop every this many cells
  double trail_min_mass_mg = 0.05;    // smaller trail drops are not left
  double trail_lifetime_s = 4.0;      // a trail drop's radius shrinks to nothing over this time
  double sub_metaball_merge_s = 0.6;  // impact sub-metaballs migrate into the main one over this
  int impact_sub_metaballs = 3;
  double sub_metaball_offset = 0.9;   // initial offset, in main radii
  double sub_metaball_radius = 0.55;  // in main radii
  // What the renderer sees of trail drops and impact sub-metaballs changes in this many steps over
  // their lives (the sim's masses change smoothly).
  int published_stages = 6;
  double particle_radius_mm = 1.8;    // particle model: 3.5 mg each as made
  double penalty = 0.25;              // repulsion: extra push as a fraction of the overlap
  int region_particle_diameters = 4;  // particle region: blade width + this many diameters a side
  int suspension_cells = 7;           // 7 x 7 search before a particle becomes a mesh drop
  double suspension_max_s = 3.0;      // a drop that never moves away holds its particles this long
  double airflow_coefficient = 0.5;   // drag coefficient of a drop in the airflow over the glass
  double airflow_fraction = 0.5;      // air speed over the glass as a fraction of the car's speed
  double airflow_spread = 0.3;  // sideways air at the side edges, as a fraction of the airflow
  double min_drop_diameter_mm = 1.0;  // smaller raindrops are mist and are not simulated
  double max_drop_diameter_mm = 6.0;
  std::uint32_t max_particles =
      20000;  // beyond this, water touched by a blade is wiped off at once
  WaterShapeConfig shape;
};

struct WindshieldConfig {
  GlassConfig glass;
  WiperConfig wipers;
  WaterConfig water;
  int sub_steps_per_water_step = 4;  // the water moves at 60 Hz with the default 240 Hz sub-step
};

// What the renderer reads each frame.
// A round drop: seed 000's metaball, now a cap of this contact radius (surface_from_metaballs).
struct Metaball {
  float u_mm = 0.0f;
  float v_mm = 0.0f;
  float radius_mm = 0.0f;
};

struct BladePose {
  glm::vec2 pivot_mm{0.0f};
  float angle_rad = 0.0f;  // direction from the pivot to the tip, counter-clockwise from +u
  float length_mm = 0.0f;
  float width_mm = 0.0f;
};

// The unit direction at `angle_rad` counter-clockwise from +u (a blade's, from its pivot), and a
// direction's left normal (a quarter turn counter-clockwise).
inline glm::dvec2 blade_direction(float angle_rad) {
  return {std::cos(angle_rad), std::sin(angle_rad)};
}
inline glm::dvec2 left_normal(glm::dvec2 d) { return {-d.y, d.x}; }

struct GlassWaterSurface;  // glass_water_surface.hpp

struct WindshieldState {
  std::vector<Metaball> metaballs;  // mesh drops (main + sub-metaballs) and particles
  // The same water as the light meets it: each body's shape (glass_water_surface.hpp); shared by
  // copies, replaced by each publish. Null: no water to refract.
  std::shared_ptr<const GlassWaterSurface> surface;
  std::array<BladePose, 2> blades;
  std::uint32_t drops = 0;          // mesh drops
  std::uint32_t particles = 0;      // particle model drops
  double glass_wet_fraction = 0.0;  // of the glass under water (GlassWaterSurface::wet_fraction)
};

}  // namespace downpour::sim
