#version 450
// The road's layer (half the view's size: the near road) brought into the view (road_pass.hpp),
// on the near road's own triangles (road_composite.vert), which give each pixel its depth and its
// edges at the view's pixels. The layer's texels hold alpha 1 where they hold road and 0
// elsewhere: a pixel takes the bilinear colour of the texels around it that hold road (over the
// alpha), so that the road's edges do not darken. The layer drew the same triangles, so a pixel
// inside them has road in at least one of its four texels (a sixteenth of the weight or more) but
// where the two disagree (a sliver thinner than a texel): there it draws nothing.
#include "common.glsl"
uniform vec2 u_inv_viewport;  // 1 / the view's size (the layer spans it, rounded up to whole texels)
out vec4 out_colour;

void main() {
  vec4 c = textureLod(road_layer_tex, gl_FragCoord.xy * u_inv_viewport, 0.0);
  if (c.a < 1.0 / 32.0) discard;
  // Display-encoded colours averaged: the texels beside one are alike but at the road's edges.
  out_colour = vec4(c.rgb / max(c.a, 1e-3), 1.0);
}
