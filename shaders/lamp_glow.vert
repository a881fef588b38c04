#version 450
// A lamp's glow (lamp_glow_pass.hpp): a square around the lamp's point on the screen, at its
// depth, reaching the halo's radius (or the core's pixel); instance i draws glow i.
#include "common.glsl"
uniform vec4 u_glows[3 * MAX_GLOWS];  // position and halo radius, colour and peak, core
uniform vec2 u_pixel;          // one pixel in clip units, x and y
out vec2 v_offset_px;
flat out vec4 v_colour;
flat out float v_radius;
flat out float v_core;
void main() {
  vec4 at = u_glows[3 * gl_InstanceID];
  v_colour = u_glows[3 * gl_InstanceID + 1];
  v_core = u_glows[3 * gl_InstanceID + 2].x;
  v_radius = at.w;
  vec2 corner = vec2(gl_VertexID & 1, gl_VertexID >> 1) * 2.0 - 1.0;
  float reach = max(at.w, 2.0) + 1.0;
  v_offset_px = corner * reach;
  vec4 clip = frame.view_proj * vec4(at.xyz, 1.0);
  clip.xy += v_offset_px * u_pixel * 0.5 * clip.w;
  gl_Position = clip;
}
