// Smooth shapes for the built-in models, added to a mesh: rounded boxes, bodies lofted through
// cross-sections, wheels. Each quad carries its own four vertices, so that a material (uv.x) or a
// trim colour (uv.y) changes exactly at a quad's edge; normals come from the smooth surface.
#pragma once

#include <functional>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "server/model/mesh_data.hpp"

namespace downpour::model {

// A quad's look: its material id and trim colour (pack_trim_colour, or 0).
struct Look {
  float material = 0.0f;
  float colour = 0.0f;
};

// A box from lo to hi whose edges and corners are rounded to `radius` (at most half its least
// side); `taper` scales its top face's x and y about the box's axis (1: none), as a cabin narrows.
void add_rounded_box(render::MeshData& m, const glm::vec3& lo, const glm::vec3& hi, float radius,
                     Look look, glm::vec2 taper = glm::vec2(1.0f), int segments = 2);

// One cross-section of a loft, across the vehicle at x: from z_bottom to z_top, half_width wide at
// its middle and half_width * top_scale at its top; `corner` (0-1) how round its corners are (0
// square, 1 an ellipse).
struct Section {
  float x = 0.0f;
  float z_bottom = 0.0f;
  float z_top = 1.0f;
  float half_width = 1.0f;
  float top_scale = 1.0f;
  float corner = 0.5f;
};

// A body through the sections (in order of x), closed at both ends; `around` points a section
// (even). `look(i, j, centre, normal)` says quad (section i to i + 1, point j to j + 1) its look
// (i -1 and n - 1: the rear and front caps); j counts from the bottom's middle round through the
// right side (-y), the top and the left. `upper_only` lofts the upper half alone, what sits on
// another body: z_bottom is then the sections' middle, where the loft begins (j 0 on the right).
using LoftLook =
    std::function<Look(int i, int j, const glm::vec3& centre, const glm::vec3& normal)>;
void add_loft(render::MeshData& m, const std::vector<Section>& sections, int around,
              const LoftLook& look, bool upper_only = false);

// A wheel about the y axis through `centre`: the tyre's tread and walls, a rim with `spokes`
// spokes on its outer face (the side away from the vehicle's middle, `outward` +1 left, -1 right;
// 0 both, a single-track vehicle's).
void add_wheel(render::MeshData& m, const glm::vec3& centre, float radius, float width,
               float outward, int spokes, float rim_colour, int around = 24);

}  // namespace downpour::model
