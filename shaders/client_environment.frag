#version 450
// An environment face from a client's picture (client_background_pass.hpp): each of the face's
// directions where the picture shows it, its edges extended beyond; depth 0 where it is the sky.
#include "common.glsl"
in vec3 v_ray;  // fullscreen_ray.vert
out vec4 out_colour;
uniform vec3 u_forward;  // the picture's camera (world, unit axes)
uniform vec3 u_right;
uniform vec3 u_up;
uniform vec2 u_tan;      // the tangents of its half fields of view
uniform vec4 u_ground;   // xyz the ground's unit normal (world)
uniform int u_has_depth;  // client_depth_tex holds the picture's depth, the view's reversed-Z
// The windshield's plane as the picture's reversed-Z depth, dot(xyz, (u, v, 1)) over it (v up),
// and the near plane: what the picture's depth puts nearer is the cabin, not the world outside.
uniform vec3 u_glass_depth;
uniform float u_near;

// Inside the cabin: nearer than the glass's plane (with a few centimetres for the pillars).
bool in_cabin(vec2 uv_up, float z) {
  float plane = dot(u_glass_depth, vec3(uv_up, 1.0));
  return z > 0.0 && plane > 0.0 && z < u_near / plane + 0.03;
}

void main() {
  vec3 dir = normalize(v_ray);
  // Behind the camera the ray runs to the picture's edge the way it leans.
  float ahead = max(dot(dir, u_forward), 1e-3);
  vec2 p = vec2(dot(dir, u_right), dot(dir, u_up)) / (ahead * u_tan);
  vec2 uv = clamp(0.5 + 0.5 * p, 0.0, 1.0);  // (the picture's rows run bottom-up, as v)
  float z = 0.0;
  if (u_has_depth != 0) {
    // Where the picture shows its own cabin (a roof, a dashboard, a pillar), the world outside
    // nearest to it towards the picture's centre.
    vec2 from = uv;
    for (int i = 0; i < 16; ++i) {
      float d = textureLod(client_depth_tex, uv, 0.0).r;
      z = d > 0.0 ? u_near / d : 0.0;
      if (!in_cabin(uv, z)) break;
      uv = mix(from, vec2(0.5), float(i + 1) / 16.0);
    }
  }
  out_colour = vec4(textureLod(client_image_tex, uv, 0.0).rgb, 1.0);
  bool sky = u_has_depth != 0 ? z == 0.0 : dot(dir, u_ground.xyz) >= 0.0;
  gl_FragDepth = sky ? 0.0 : 0.5;
}
