#version 450
// The environment probe along each of the view's rays, at its finest level
// (environment_background_pass.hpp).
#include "common.glsl"
in vec3 v_ray;  // fullscreen_ray.vert
out vec4 out_colour;
uniform mat4 u_env_from_world;  // world directions into the probe's axes
void main() {
  vec3 dir = normalize(v_ray);
  out_colour = vec4(to_display(textureLod(environment_tex, mat3(u_env_from_world) * dir, 0.0).rgb), 1.0);
}
