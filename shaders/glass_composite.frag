#version 450
// The glass layer over the view at full size, premultiplied: its bilinear magnification is the
// rest of the lens's blur. Drawn on the glass's own geometry, depth-tested, so the cabin (pillars,
// dashboard, mirror) stays in front of the water.
#include "interface.glsl"
in vec2 v_glass_mm;
in vec3 v_world;
out vec4 out_colour;
uniform vec2 u_inv_viewport;
void main() {
  vec4 layer = texture(glass_layer_tex, gl_FragCoord.xy * u_inv_viewport);
  if (layer.a < 0.002) discard;
  out_colour = layer;
}
