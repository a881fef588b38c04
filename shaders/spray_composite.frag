#version 450
// The spray layer (reduced size, premultiplied) over the view, bilinear.
#include "common.glsl"
in vec2 v_uv;
out vec4 out_colour;
void main() { out_colour = textureLod(spray_layer_tex, v_uv, 0.0); }
