#version 450
// Rain streaks over the scene (seed 004): the CPU's rain layer (rain_layer.hpp), at reduced size,
// upsampled. The cars have already hidden the streaks behind them in the layer; the depth test on
// rain.vert's plane keeps the rain off the cabin.
#include "common.glsl"
in vec2 v_uv;
layout(location = 0) out vec4 out_colour;
void main() {
  out_colour = texture(rain_layer_tex, v_uv);
}
