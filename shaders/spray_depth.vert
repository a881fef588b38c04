#version 450
// Seed 001, step 3, on a GPU: each liquid parcel as a square facing the camera, in front of its
// sphere and large enough to cover its outline; the fragment shader casts the pixel's ray at the
// sphere. (On llvmpipe the CPU draws the same maps: spray_splat.hpp.)
#include "interface.glsl"
layout(std430, binding = PARCELS_BUFFER) readonly buffer Parcels {
  vec4 parcels[];  // view-space centre, radius (m)
};
uniform mat4 u_projection;
uniform int u_spray_count;  // the first u_spray_count parcels are spray, the rest the body's
uniform float u_near;
flat out vec4 v_centre;
flat out int v_body;
out vec3 v_ray;  // the view-space point of the square under the fragment
void main() {
  vec4 p = parcels[gl_InstanceID];
  vec2 corner = vec2(gl_VertexID & 1, gl_VertexID >> 1) * 2.0 - 1.0;
  // In front of the sphere, but never nearer than the near plane (the square grows with its
  // distance to cover the same outline).
  float front = min(p.z + p.w, -1.01 * u_near);
  vec3 q = vec3((p.xy + corner * p.w * 1.3) * (front / min(p.z + p.w, -1e-4)), front);
  v_centre = p;
  v_body = gl_InstanceID >= u_spray_count ? 1 : 0;
  v_ray = q;
  gl_Position = u_projection * vec4(q, 1.0);
}
