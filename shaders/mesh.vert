#version 450
#include "common.glsl"
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec2 a_uv;
uniform mat4 u_model;
out vec3 v_world;
out vec3 v_normal;
out vec2 v_uv;
out vec4 v_fog;
void main() {
  vec4 world = u_model * vec4(a_position, 1.0);
  v_world = world.xyz;
  v_normal = mat3(u_model) * a_normal;
  v_uv = a_uv;
  v_fog = fog_at(world.xyz);
  gl_Position = frame.view_proj * world;
  // The road reflection keeps what is above the road; other frames' plane keeps everything (a
  // distance written is a distance used on llvmpipe, enabled or not).
  gl_ClipDistance[0] = dot(frame.clip_plane.xyz, world.xyz) + frame.clip_plane.w;
}
