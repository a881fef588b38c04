#version 450
// A client-background view's picture as its colour, and the depth behind it: the picture's own,
// else the ground's (client_background_pass.hpp; cpu/client_background.cpp draws the same ground).
#include "common.glsl"
in vec2 v_uv;
out vec4 out_colour;
uniform vec3 u_forward;   // the camera's axis (world, unit)
uniform vec3 u_right_tan; // its right and up, times the tangents of its half fields of view
uniform vec3 u_up_tan;
uniform vec4 u_ground;    // xyz the ground's unit normal (world), w the camera's height above it
uniform float u_near;     // the projection's near plane (reversed-Z: depth = near / distance)
uniform int u_has_depth;
void main() {
  vec2 uv = vec2(v_uv.x, 1.0 - v_uv.y);  // the picture's rows run from the top
  out_colour = vec4(textureLod(client_image_tex, uv, 0.0).rgb, 1.0);
  float z;
  if (u_has_depth != 0) {
    z = textureLod(client_depth_tex, uv, 0.0).r;
  } else {
    vec2 p = v_uv * 2.0 - 1.0;
    float down = -dot(u_ground.xyz, u_forward + p.x * u_right_tan + p.y * u_up_tan);
    z = down > 1e-6 && u_ground.w > 0.0 ? u_ground.w / down : 0.0;
  }
  gl_FragDepth = z > 0.0 ? min(u_near / z, 1.0) : 0.0;
}
