#version 450
// The lamps of the frame's lamp block into an environment probe's face (environment_probe.hpp),
// seen from the probe (the face's camera): a point each, five texels wide, at the lamp (a little
// towards the probe, in front of its own housing), holding the light it sends there.
#include "common.glsl"
uniform float u_texel_rad;  // a texel's angle at the face's centre
out vec3 v_light;           // radiance per unit of the spot's weight
void main() {
  int i = gl_VertexID;
  vec3 lamp = lamps.lamp[4 * i].xyz, probe = frame.camera_pos.xyz;
  vec3 to_probe = probe - lamp;
  float d = length(to_probe);
  gl_Position = frame.view_proj * vec4(lamp + to_probe * (0.15 / max(d, 0.3)), 1.0);
  vec2 xy = gl_Position.xy / max(gl_Position.w, 1e-6);
  // A texel's solid angle there: the face's centre's, less towards its corners.
  float q = 1.0 + dot(xy, xy);
  float texel_sr = u_texel_rad * u_texel_rad / (q * sqrt(q));
  // Its illuminance at the probe (facing it), through the haze, as pi times the radiance a white
  // card shows.
  vec3 lux = lamp_lux(i, probe, -to_probe / max(d, 1e-3)) * exp(-frame.fog.a * d);
  v_light = lux * (3.14159265 * frame.lamp_map.y / texel_sr);
  gl_PointSize = 5.0;
}
