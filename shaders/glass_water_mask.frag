#version 450
// Where the water pass may find water (glass_water_mask_pass.hpp): the glass layer's pixels whose
// footprint on the glass touches a cell of the surface's grid that lists a body. Writes the
// farthest depth there (the layer is cleared to the nearest), so that the optics, depth-tested
// nearer, run there alone.
#include "common.glsl"
#include "glass_surface.glsl"
in vec2 v_glass_mm;
in vec3 v_world;
bool listed(vec2 p) { return (cell_listing(p) & ((1u << u_count_bits) - 1u)) != 0u; }
void main() {
  // The footprint's corners and centre: every cell under a footprint up to two cells wide.
  vec2 dx = 0.5 * dFdx(v_glass_mm), dy = 0.5 * dFdy(v_glass_mm);
  if (!(listed(v_glass_mm) || listed(v_glass_mm - dx - dy) || listed(v_glass_mm + dx - dy) ||
        listed(v_glass_mm - dx + dy) || listed(v_glass_mm + dx + dy)))
    discard;
  gl_FragDepth = 0.0;
}
