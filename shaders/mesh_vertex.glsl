// A static mesh in world space (mesh.vert); with MESH_IN_CAR, in the car's frame, placed on the
// screen by u_clip_from_car (cabin.vert); with MESH_CURVATURE, its vertices' principal
// curvatures and directions passed on for the relief shadows (road.vert); with MESH_WHEELS, a
// vehicle or cabin model whose wheels turn (model.vert).
#include "common.glsl"
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec2 a_uv;
uniform mat4 u_model;
#ifdef MESH_IN_CAR
uniform mat4 u_clip_from_car;
#endif
out vec3 v_world;
out vec3 v_normal;
out vec2 v_uv;
out vec4 v_fog;
#ifdef MESH_CURVATURE
layout(location = 3) in vec2 a_curvature;      // k1, k2 (1/m, convex positive)
layout(location = 4) in vec4 a_principal_dirs;  // v1, v2 in (u, v)
out vec2 v_curvature;
out vec4 v_principal_dirs;
// The road drawn in two parts, near and far of x metres from the camera: y = 1 keeps the near
// part, -1 the far (the same distance negated, so that the parts meet without a crack).
uniform vec2 u_near_split;
// And a plane that keeps a range of the view's depth (road_pass.hpp's RoadPart): xyz . world + w
// at least 0 is kept; (0, 0, 0, 1) keeps all.
uniform vec4 u_depth_clip;
#endif
#ifdef MESH_WHEELS
// Wheel k's vertices [u_wheel_vertices[k].x, .y) turn about the axle through (x, z) =
// u_wheel_turn[k].xy of the model's frame, by the angle whose cosine and sine are .zw
// (model_meshes.hpp: the whole model in one draw).
#define MAX_WHEELS 16
uniform int u_wheel_count;
uniform ivec2 u_wheel_vertices[MAX_WHEELS];
uniform vec4 u_wheel_turn[MAX_WHEELS];
// Where the vertex reads the model's textures (mesh_data.hpp's VertexTexture: uv, layer or -1).
layout(location = 6) in vec3 a_texture;
#endif
out vec3 v_texture;  // (-1: no texture, for the meshes without them)
#ifdef ROAD_LANES
layout(location = 5) in vec4 a_lane;  // mesh_data.hpp's VertexLane
flat out vec4 v_strip;
#endif
void main() {
  vec3 position = a_position, normal = a_normal;
#ifdef MESH_WHEELS
  for (int k = 0; k < u_wheel_count; ++k) {
    ivec2 range = u_wheel_vertices[k];
    if (gl_VertexID >= range.x && gl_VertexID < range.y) {
      vec4 turn = u_wheel_turn[k];
      vec2 p = position.xz - turn.xy;
      position.xz = turn.xy + vec2(turn.z * p.x + turn.w * p.y, turn.z * p.y - turn.w * p.x);
      normal.xz = vec2(turn.z * normal.x + turn.w * normal.z, turn.z * normal.z - turn.w * normal.x);
    }
  }
#endif
  vec4 world = u_model * vec4(position, 1.0);
  v_world = world.xyz;
  v_normal = mat3(u_model) * normal;
  v_uv = a_uv;
#ifdef MESH_IN_CAR
  v_fog = vec4(0.0);  // (the cabin is not fogged)
#else
  v_fog = fog_at(world.xyz);
#endif
#ifdef MESH_CURVATURE
  v_curvature = a_curvature;
  v_principal_dirs = a_principal_dirs;
#endif
#ifdef ROAD_LANES
  v_strip = a_lane;
#endif
#ifdef MESH_WHEELS
  v_texture = a_texture;
#else
  v_texture = vec3(0.0, 0.0, -1.0);
#endif
#ifdef MESH_IN_CAR
  gl_Position = u_clip_from_car * world;
  gl_ClipDistance[0] = 1.0;  // (the cabin is never in the road's mirror)
#else
  gl_Position = frame.view_proj * world;
  // The road reflection keeps what is above the road; other frames' plane keeps everything (a
  // distance written is a distance used on llvmpipe, enabled or not).
  gl_ClipDistance[0] = dot(frame.clip_plane.xyz, world.xyz) + frame.clip_plane.w;
#endif
#ifdef MESH_CURVATURE
  gl_ClipDistance[1] = u_near_split.y * (u_near_split.x - distance(world.xyz, frame.camera_pos.xyz));
  gl_ClipDistance[2] = dot(u_depth_clip.xyz, world.xyz) + u_depth_clip.w;
#endif
}
