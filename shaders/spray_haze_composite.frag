#version 450
// The haze over the spray layer: the light the droplets scatter (the sky's and the scene's, and
// the lamps' where their beams pass) times their coverage
// 1 - exp(-tau), faded where the scene lies nearer than the cloud's mean distance (soft
// particles, over u_soft_m), the haze map softened by four bilinear taps a texel apart (a parcel
// stands for a cloud whose edge is not sharp). Premultiplied.
#include "common.glsl"
in vec2 v_uv;
uniform vec3 u_light;  // linear: the sky's and the scene's
uniform float u_near;
uniform float u_soft_m;
out vec4 out_colour;
void main() {
  vec2 t = 0.75 / vec2(textureSize(spray_haze_tex, 0));
  vec2 h = 0.25 * (textureLod(spray_haze_tex, v_uv + vec2(-t.x, -t.y), 0.0).rg +
                   textureLod(spray_haze_tex, v_uv + vec2(t.x, -t.y), 0.0).rg +
                   textureLod(spray_haze_tex, v_uv + vec2(-t.x, t.y), 0.0).rg +
                   textureLod(spray_haze_tex, v_uv + vec2(t.x, t.y), 0.0).rg);
  if (h.x <= 1e-4) discard;
  float z = h.y / h.x;
  float scene = u_near / max(textureLod(view_depth_tex, v_uv, 0.0).r, 1e-12);
  float alpha = (1.0 - exp(-h.x)) * clamp((scene - z) / u_soft_m + 0.5, 0.0, 1.0);
  // And the lamps' (a beam through the mist glows), at the cloud's mean distance along the ray.
  out_colour = vec4(to_display(haze_radiance(v_uv, z, u_light)) * alpha, alpha);
}
