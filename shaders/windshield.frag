#version 450
// The WINDSHIELD view: the glass in its own plane fitted to the view. Dry glass is black; water is
// grey by the height of the surface that the COCKPIT view traces (glass_surface.glsl: 0.35 at its
// edge up to 1 at 1.5 mm); the outline is faint grey so that the image shows where the glass is;
// wiper blades are blue.
#include "interface.glsl"
#include "glass_surface.glsl"
#include "wiper_blades.glsl"
in vec2 v_uv;
out vec4 out_colour;
uniform vec3 u_glass_mm;     // bottom width, top width, height
uniform float u_aspect;
void main() {
  float scale = max(u_glass_mm.x / u_aspect, u_glass_mm.z) * 1.1;  // mm across the view's height
  vec2 p = (v_uv - 0.5) * vec2(u_aspect, 1.0) * scale;             // mm from the glass's centre
  vec2 mm = p + 0.5 * u_glass_mm.xz;                                // glass space
  float half_width = 0.5 * mix(u_glass_mm.x, u_glass_mm.y, clamp(mm.y / u_glass_mm.z, 0.0, 1.0));
  float edge_dist = min(half_width - abs(p.x), min(mm.y, u_glass_mm.z - mm.y));
  float px = fwidth(p.x);
  float inside = clamp(edge_dist / px + 0.5, 0.0, 1.0);
  float outline = inside * (1.0 - smoothstep(px, 2.0 * px, edge_dist));

  uint top;
  float height = 0.0, covered = 0.0;
  if (water_top(mm, top)) {
    WaterSurface s = body_surface(body_at(top), mm);
    height = s.height;
    // Anti-aliased over a pixel at the edge, where the height falls by its slope.
    covered = clamp(height / (max(length(s.slope), 0.05) * px) + 0.5, 0.0, 1.0);
  }
  float grey = 0.35 + 0.65 * clamp(height / 1.5, 0.0, 1.0);
  vec3 colour = vec3(max(0.25 * outline, grey * covered * inside));
  vec2 wiper = wiper_coverage(mm, px);
  colour = mix(colour, vec3(0.05, 0.12, 0.45), wiper.y);
  colour = mix(colour, vec3(0.15, 0.35, 1.0), wiper.x);
  out_colour = vec4(colour, 1.0);
}
