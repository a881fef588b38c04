#version 450
// The refraction background (seed 000, section 1.5 step 5): the view so far at a quarter of its
// size, each texel the mean of its 4 x 4 pixels (four bilinear taps). The cabin (what lies on the
// driver's side of the glass: pillars, mirror, dashboard) is not seen through the water: its pixels
// become the horizon's colour, so that blurred drops do not smear it over the glass.
#include "common.glsl"
in vec2 v_uv;
out vec4 out_colour;
layout(binding = 7) uniform sampler2D view_colour;
layout(binding = 8) uniform sampler2D view_depth;
uniform vec2 u_texel;        // one view pixel in uv
uniform vec3 u_glass_depth;  // the glass plane's depth over the view: dot(xyz, (uv, 1))

vec3 outside(vec2 uv, vec3 cabin_colour) {
  vec3 colour = textureLod(view_colour, uv, 0.0).rgb;
  // Reversed-Z: nearer is greater; the plane's depth is affine over the view.
  float depth = textureLod(view_depth, uv, 0.0).r;
  return depth > dot(u_glass_depth, vec3(uv, 1.0)) ? cabin_colour : colour;
}

void main() {
  vec2 d = u_texel;
  vec3 cabin = to_display(frame.sky_horizon.rgb);
  vec3 sum = outside(v_uv + vec2(-d.x, -d.y), cabin) + outside(v_uv + vec2(d.x, -d.y), cabin) +
             outside(v_uv + vec2(-d.x, d.y), cabin) + outside(v_uv + vec2(d.x, d.y), cabin);
  out_colour = vec4(0.25 * sum, 1.0);
}
