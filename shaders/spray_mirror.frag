#version 450
// The spray's haze over the road's mirror (spray_mirror_pass.hpp), lit as the view's haze is
// (spray_haze_composite.frag): the droplets' light, the sky's and the scene's and the lamps' where
// their beams pass, times their coverage 1 - exp(-tau), premultiplied, at the clouds' mean
// distance (reversed-Z), so that the mirror's nearer surfaces hide it. The frame block holds the
// mirrored camera (haze_radiance, common.glsl).
#include "common.glsl"
in vec2 v_uv;
uniform vec3 u_light;  // linear: the sky's and the scene's
uniform float u_near;
out vec4 out_colour;
void main() {
  vec2 h = textureLod(spray_mirror_haze_tex, v_uv, 0.0).rg;
  if (h.x <= 1e-3) discard;
  float z = h.y / h.x;
  float alpha = 1.0 - exp(-h.x);
  gl_FragDepth = u_near / max(z, u_near);
  out_colour = vec4(to_display(haze_radiance(v_uv, z, u_light)) * alpha, alpha);
}
