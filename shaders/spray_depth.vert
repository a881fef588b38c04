#version 450
// Seed 001, step 3, on a GPU: each liquid parcel as a square facing the camera, in front of its
// sphere and large enough to cover its outline; the fragment shader casts the pixel's ray at the
// sphere. (On llvmpipe the CPU draws the same maps: spray_splat.hpp.)
layout(std430, binding = 1) readonly buffer Parcels {
  vec4 parcels[];  // view-space centre, radius (m)
};
uniform mat4 u_projection;
uniform int u_body_count;  // the first u_body_count parcels are the body's, the rest spray
flat out vec4 v_centre;
flat out int v_body;
out vec3 v_ray;  // the view-space point of the square under the fragment
void main() {
  vec4 p = parcels[gl_InstanceID];
  vec2 corner = vec2(gl_VertexID & 1, gl_VertexID >> 1) * 2.0 - 1.0;
  vec3 q = p.xyz + vec3(corner * p.w * 1.3, p.w);
  v_centre = p;
  v_body = gl_InstanceID < u_body_count ? 1 : 0;
  v_ray = q;
  gl_Position = u_projection * vec4(q, 1.0);
}
