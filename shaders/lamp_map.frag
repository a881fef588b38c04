#version 450
// One lamp's light on the ground over its footprint (lamp_map.vert), added into a ring of the lamp
// map: on the plane of the ground under the lamp, less the cut that bounds the footprint
// (light_set.hpp's kGroundCutLux), times the exposure.
#include "common.glsl"
flat in int v_lamp;
in vec2 v_xy;
out vec4 out_light;
const float kGroundCutLux = 1.0;
void main() {
  vec3 e = lamp_lux(v_lamp, vec3(v_xy, lamps.lamp[4 * v_lamp].w), vec3(0.0, 0.0, 1.0));
  out_light = vec4(min(max(e - kGroundCutLux, 0.0) * frame.lamp_map.y, vec3(60000.0)), 0.0);
}
