#version 450
// The near road's triangles for its composite (road_composite.frag): where they lie and their
// depth, up to u_depth_clip's plane (the split). Nothing else: the layer holds their colour.
#include "common.glsl"
layout(location = 0) in vec3 a_position;
uniform vec4 u_depth_clip;  // xyz . world + w at least 0 is kept
void main() {
  gl_Position = frame.view_proj * vec4(a_position, 1.0);
  // (A distance written is a distance used on llvmpipe: the planes this pass does not clip by
  // keep everything.)
  gl_ClipDistance[0] = 1.0;
  gl_ClipDistance[1] = 1.0;
  gl_ClipDistance[2] = dot(u_depth_clip.xyz, a_position) + u_depth_clip.w;
}
