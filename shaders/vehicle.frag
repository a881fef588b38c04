#version 450
#include "common.glsl"
in vec3 v_world;
in vec3 v_normal;
in vec2 v_uv;  // x material id (vehicle_geometry.hpp)
in vec4 v_fog;
out vec4 out_colour;
uniform vec3 u_body_colour;
void main() {
  vec3 n = normalize(v_normal);
  vec3 view = normalize(frame.camera_pos.xyz - v_world);
  n = dot(n, view) < 0.0 ? -n : n;
  int material = int(v_uv.x + 0.5);
  vec3 albedo = u_body_colour;
  float r0 = 0.04, gloss = 1.0;
  vec3 emit = vec3(0.0);
  if (material == 1) { albedo = vec3(0.02, 0.025, 0.03); r0 = 0.06; }       // glass
  else if (material == 2) { albedo = vec3(0.02); gloss = 0.1; }              // tyre
  else if (material == 3) { albedo = vec3(0.3, 0.02, 0.02); emit = vec3(0.6, 0.03, 0.02); }  // lamp
  else if (material == 4) { albedo = vec3(0.03); gloss = 0.2; }              // trim
  vec3 colour = albedo * diffuse_light(n) + emit;
  float f = schlick(dot(n, view), r0);
  colour += sky_gradient(reflect(-view, n)) * f * gloss;
  out_colour = vec4(to_display(apply_fog(colour, v_fog)), 1.0);
}
