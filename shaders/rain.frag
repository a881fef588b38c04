#version 450
// Rain streaks over the scene (seed 004): the CPU's rain layer (rain_layer.hpp), at reduced size,
// upsampled; each texel at the depth of its nearest streak (or, beside one, of its neighbour's), so
// that the depth test hides the rain behind what is nearer (the cabin, the car ahead).
#include "common.glsl"
in vec2 v_uv;
uniform float u_near;  // the camera's near plane: reversed-Z depth is near / distance
layout(location = 0) out vec4 out_colour;
void main() {
  float depth_m = texelFetch(rain_depth_tex, ivec2(v_uv * vec2(textureSize(rain_depth_tex, 0))), 0).r;
  if (depth_m <= 0.0) discard;  // no streak in or beside this texel
  vec4 colour = texture(rain_layer_tex, v_uv);
  if (colour.a < 0.002) discard;
  gl_FragDepth = u_near / depth_m;
  out_colour = colour;
}
