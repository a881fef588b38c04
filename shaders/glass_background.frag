#version 450
// The refraction background (seed 000, section 1.5 step 5): the view so far at an eighth of its
// size, each texel the mean of its 8 x 8 pixels (16 bilinear taps, each the mean of 2 x 2). The cabin (what lies on the
// driver's side of the glass: pillars, mirror, dashboard) is not seen through the water: its pixels
// become the horizon's colour, so that blurred drops do not smear it over the glass. At night a
// lamp is a few bright pixels that the mean would lose: the brightest tap's excess over 0.6 is
// kept as well, so that each drop in front of a lamp refracts a bright point of it (the lamps
// bloom through the wet glass).
#include "common.glsl"
in vec2 v_uv;
out vec4 out_colour;
uniform vec2 u_texel;        // one view pixel in uv
uniform vec3 u_glass_depth;  // the glass plane's depth over the view: dot(xyz, (uv, 1))

vec3 outside(vec2 uv, vec3 cabin_colour) {
  vec3 colour = textureLod(view_colour_tex, uv, 0.0).rgb;
  // Reversed-Z: nearer is greater; the plane's depth is affine over the view.
  float depth = textureLod(view_depth_tex, uv, 0.0).r;
  return depth > dot(u_glass_depth, vec3(uv, 1.0)) ? cabin_colour : colour;
}

void main() {
  vec3 cabin = to_display(frame.sky_horizon.rgb);
  vec3 sum = vec3(0.0), peak = vec3(0.0);
  for (int j = 0; j < 4; ++j) {
    for (int i = 0; i < 4; ++i) {
      vec3 c = outside(v_uv + (vec2(i, j) * 2.0 - 3.0) * u_texel, cabin);
      sum += c;
      peak = max(peak, c);
    }
  }
  // (By night and dusk: by day the bright sky would be a highlight too.)
  float night = smoothstep(1e-3, 1e-2, frame.lamp_map.y);
  out_colour = vec4(sum / 16.0 + max(peak - 0.6, 0.0) * (1.5 * night), 1.0);
}
