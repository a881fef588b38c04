#version 450
// The road's layer (half the view's size: the near road) brought into the view (road_pass.hpp).
// Its texels hold alpha 1 and their depth where they hold road, alpha 0 and depth 0 (the far
// plane) elsewhere: a pixel is road where the bilinear alpha is at least a half (an edge as fine
// as the view's pixels, not the layer's) and its depth is nearer than the split (the far road,
// drawn whole, takes over there); it takes the bilinear colour and depth of the texels around it
// that hold road (both sampled bilinear, over the alpha).
#include "common.glsl"
uniform float u_min_depth;     // reversed-Z: the split's
uniform vec2 u_inv_viewport;  // 1 / the view's size (the layer spans it, rounded up to whole texels)
out vec4 out_colour;

void main() {
  vec2 uv = gl_FragCoord.xy * u_inv_viewport;
  vec4 c = textureLod(road_layer_tex, uv, 0.0);
  float depth = textureLod(road_layer_depth_tex, uv, 0.0).r / max(c.a, 1e-3);
  if (c.a < 0.5 || depth < u_min_depth) discard;
  // Display-encoded colours averaged: the texels beside one are alike but at the road's edges.
  out_colour = vec4(c.rgb / c.a, 1.0);
  gl_FragDepth = depth;
}
