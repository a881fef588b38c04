#version 450
// One lamp's footprint on the ground (its box, light_set.hpp's lamp_footprint) as a quad over one
// ring of the lamp map (lamp_map.hpp); instance i draws lamp i.
#include "common.glsl"
uniform int u_ring;
uniform vec4 u_boxes[MAX_LAMPS];  // x0 y0 x1 y1 (world m)
flat out int v_lamp;
out vec2 v_xy;
void main() {
  vec4 box = u_boxes[gl_InstanceID];
  vec2 corner = vec2(gl_VertexID & 1, gl_VertexID >> 1);
  v_xy = mix(box.xy, box.zw, corner);
  v_lamp = gl_InstanceID;
  vec4 ring = frame.lamp_rings[u_ring];
  gl_Position = vec4((v_xy - ring.xy) * ring.z * 2.0 - 1.0, 0.0, 1.0);
}
