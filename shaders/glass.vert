#version 450
// The windshield trapezoid at its place in the world, with its glass-space coordinates (mm).
#include "common.glsl"
uniform vec3 u_glass_origin;  // the bottom-left corner, world
uniform vec3 u_glass_u;       // unit axes, world
uniform vec3 u_glass_v;
uniform vec3 u_glass_mm;  // bottom width, top width, height
out vec2 v_glass_mm;
out vec3 v_world;
void main() {
  float inset = 0.5 * (u_glass_mm.x - u_glass_mm.y);
  vec2 corners[4] = vec2[](vec2(0.0), vec2(u_glass_mm.x, 0.0), vec2(inset, u_glass_mm.z),
                           vec2(u_glass_mm.x - inset, u_glass_mm.z));
  v_glass_mm = corners[gl_VertexID];
  v_world = u_glass_origin + (v_glass_mm.x * u_glass_u + v_glass_mm.y * u_glass_v) * 1e-3;
  gl_Position = frame.view_proj * vec4(v_world, 1.0);
}
