// Seed 001's screen-space liquid, shared by its passes: view-space points from the spray's depth
// maps (distances along the view axis, metres; kFar where nothing is), at the spray's reduced size.
#include "common.glsl"
const float kFar = 1.0e6;
uniform vec2 u_size;  // the spray layer's size in pixels
uniform vec2 u_tan;   // tan of the half field of view, x and y

// The view-space point at distance z along the view axis through pixel centre px (continuous).
vec3 view_point(vec2 px, float z) {
  vec2 ndc = px / u_size * 2.0 - 1.0;
  return vec3(ndc * u_tan * z, -z);
}
// The pixel (continuous) a view-space point projects to.
vec2 pixel_of(vec3 p) { return ((p.xy / (-p.z * u_tan)) * 0.5 + 0.5) * u_size; }
