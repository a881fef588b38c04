#version 450
// The wiper blades on the glass, premultiplied alpha: rubber near black, the arms dark grey with a
// little sky sheen; edges soft over a pixel (or the blur of a close camera). Beyond the glass (the
// pivots under the cowl) they are hidden.
#include "common.glsl"
#include "wiper_blades.glsl"
in vec2 v_glass_mm;
out vec4 out_colour;
uniform float u_blur_mm;
uniform vec3 u_glass_mm;  // bottom width, top width, height
void main() {
  float inset = 0.5 * (u_glass_mm.x - u_glass_mm.y) * v_glass_mm.y / u_glass_mm.z;
  vec2 wiper = wiper_coverage(v_glass_mm, max(length(fwidth(v_glass_mm)), u_blur_mm));
  bool on_glass = v_glass_mm.y >= 0.0 && v_glass_mm.y <= u_glass_mm.z &&
                  v_glass_mm.x >= inset && v_glass_mm.x <= u_glass_mm.x - inset;
  if (!on_glass || wiper.x + wiper.y <= 0.0) discard;
  vec3 arm = vec3(0.045) + 0.04 * frame.sky_horizon.rgb;
  vec4 result = vec4(arm, 1.0) * wiper.y;
  out_colour = mix(result, vec4(vec3(0.012), 1.0), wiper.x);
}
