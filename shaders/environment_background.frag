#version 450
// The environment probe along each of the view's rays, at its finest level
// (environment_background_pass.hpp).
#include "common.glsl"
in vec2 v_uv;
out vec4 out_colour;
uniform mat4 u_env_from_world;  // world directions into the probe's axes
void main() {
  vec4 far_point = frame.inv_view_proj * vec4(v_uv * 2.0 - 1.0, 1e-6, 1.0);
  vec3 dir = normalize(far_point.xyz / far_point.w - frame.camera_pos.xyz);
  out_colour = vec4(to_display(textureLod(environment_tex, mat3(u_env_from_world) * dir, 0.0).rgb), 1.0);
}
