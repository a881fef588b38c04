// Where the water pass may find water (glass_water_mask_pass.hpp), shared by its programs:
// glass_water_mask.frag (the layer's pixels whose footprint on the glass touches a cell of the
// surface's grid that lists a body: for the optics' grids of 4 or 16 samples) and
// glass_water_mask_pair.frag (GLASS_PAIR: the pixels where a cell under one of the pair's two
// samples lists a body, the very cells the pair's search walks). Writes the farthest depth there
// (the layer is cleared to the nearest), so that the optics, depth-tested nearer, run there alone.
#include "common.glsl"
#include "glass_surface.glsl"
in vec2 v_glass_mm;
in vec3 v_world;
bool listed(vec2 p) { return (cell_listing(p) & ((1u << u_count_bits) - 1u)) != 0u; }
void main() {
  vec2 dx = dFdx(v_glass_mm), dy = dFdy(v_glass_mm);
#ifdef GLASS_PAIR
  vec2 p0, p1;
  pair_samples(v_glass_mm, dx, dy, p0, p1);
  if (!(listed(p0) || listed(p1))) discard;
#else
  // The footprint's corners and centre: every cell under a footprint up to two cells wide.
  dx *= 0.5;
  dy *= 0.5;
  if (!(listed(v_glass_mm) || listed(v_glass_mm - dx - dy) || listed(v_glass_mm + dx - dy) ||
        listed(v_glass_mm - dx + dy) || listed(v_glass_mm + dx + dy)))
    discard;
#endif
  gl_FragDepth = 0.0;
}
