#version 450
// A parcel's cloud: optical depth 2 tau0 (1 - b^2)^2 at b of its radius from the centre (thinning
// to its edge, with the extinction over its disc of a ball of even density), added up with its
// distance times it (RG32F, additive): the clouds all scatter the same light, so the order does
// not matter.
in vec2 v_corner;
flat in float v_depth;
flat in float v_z;
out vec2 out_haze;
void main() {
  float b2 = dot(v_corner, v_corner);
  if (b2 >= 1.0) discard;
  float edge = 1.0 - b2;
  float tau = 2.0 * v_depth * edge * edge;
  out_haze = vec2(tau, tau * v_z);
}
