#version 450
// The WINDSHIELD view: the glass in its own plane fitted to the view. Dry glass is black; water is
// grey by its compressed height (0.35 at the threshold up to 1 a quarter above it); the outline is
// faint grey so that the image shows where the glass is; wiper blades are blue.
#include "interface.glsl"
#include "wiper_blades.glsl"
in vec2 v_uv;
out vec4 out_colour;
uniform vec3 u_glass_mm;     // bottom width, top width, height
uniform vec2 u_map_size_mm;  // the glass water map covers [0, size] of glass space
uniform float u_aspect;
uniform float u_threshold;
void main() {
  float scale = max(u_glass_mm.x / u_aspect, u_glass_mm.z) * 1.1;  // mm across the view's height
  vec2 p = (v_uv - 0.5) * vec2(u_aspect, 1.0) * scale;             // mm from the glass's centre
  vec2 mm = p + 0.5 * u_glass_mm.xz;                                // glass space
  float half_width = 0.5 * mix(u_glass_mm.x, u_glass_mm.y, clamp(mm.y / u_glass_mm.z, 0.0, 1.0));
  float edge_dist = min(half_width - abs(p.x), min(mm.y, u_glass_mm.z - mm.y));
  float px = fwidth(p.x);
  float inside = clamp(edge_dist / px + 0.5, 0.0, 1.0);
  float outline = inside * (1.0 - smoothstep(px, 2.0 * px, edge_dist));

  vec4 water = textureLod(glass_water_tex, mm / u_map_size_mm, 0.0);
  float grey = 0.35 + 0.65 * clamp((water.b - u_threshold) * 4.0, 0.0, 1.0);
  vec3 colour = vec3(max(0.25 * outline, grey * water.a * inside));
  vec2 wiper = wiper_coverage(mm, px);
  colour = mix(colour, vec3(0.05, 0.12, 0.45), wiper.y);
  colour = mix(colour, vec3(0.15, 0.35, 1.0), wiper.x);
  out_colour = vec4(colour, 1.0);
}
