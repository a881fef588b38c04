#version 450
// One wiper blade's footprint on the glass (instance = blade): the rectangle from a little behind
// its pivot to its tip, wide enough for the rubber and the arm, placed in the world like the glass.
#include "common.glsl"
#include "wiper_blades.glsl"
uniform vec3 u_glass_origin;  // the bottom-left corner, world
uniform vec3 u_glass_u;       // unit axes, world
uniform vec3 u_glass_v;
uniform float u_margin_mm;  // for the soft edges
out vec2 v_glass_mm;
void main() {
  int blade = gl_InstanceID;
  vec2 pivot = u_blade_pivot_dir[blade].xy;
  vec2 dir = u_blade_pivot_dir[blade].zw;
  float len = u_blade_size[blade].x;
  float w = u_blade_size[blade].y;
  vec2 corner = vec2(gl_VertexID & 1, gl_VertexID >> 1);
  float along = mix(-w - u_margin_mm, len + u_margin_mm, corner.x);
  float across = mix(-w - u_margin_mm, w + u_margin_mm, corner.y);
  v_glass_mm = pivot + along * dir + across * vec2(-dir.y, dir.x);
  vec3 world = u_glass_origin + (v_glass_mm.x * u_glass_u + v_glass_mm.y * u_glass_v) * 1e-3;
  gl_Position = frame.view_proj * vec4(world, 1.0);
}
