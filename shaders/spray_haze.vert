#version 450
// The spray's haze on a GPU: each parcel's cloud of droplets as a square facing the camera. (On
// llvmpipe the CPU draws the same map: spray_splat.hpp.)
#include "interface.glsl"
layout(std430, binding = HAZE_BUFFER) readonly buffer Haze {
  vec4 haze[];  // per parcel two: view-space centre, radius; x optical depth through the centre
};
uniform mat4 u_projection;
out vec2 v_corner;
flat out float v_depth;
flat out float v_z;
void main() {
  vec4 p = haze[2 * gl_InstanceID];
  v_corner = vec2(gl_VertexID & 1, gl_VertexID >> 1) * 2.0 - 1.0;
  v_depth = haze[2 * gl_InstanceID + 1].x;
  v_z = -p.z;
  gl_Position = u_projection * vec4(p.xyz + vec3(v_corner * p.w, 0.0), 1.0);
}
