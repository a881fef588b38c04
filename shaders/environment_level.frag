#version 450
// One mip level of an environment probe's face: each texel the mean of the four under it in the
// level above (environment_probe.hpp).
#include "interface.glsl"
out vec4 out_colour;
uniform int u_layer;  // the face
void main() {
  ivec2 at = ivec2(gl_FragCoord.xy) * 2;
  vec4 sum = texelFetch(environment_levels_tex, ivec3(at, u_layer), 0) +
             texelFetch(environment_levels_tex, ivec3(at + ivec2(1, 0), u_layer), 0) +
             texelFetch(environment_levels_tex, ivec3(at + ivec2(0, 1), u_layer), 0) +
             texelFetch(environment_levels_tex, ivec3(at + ivec2(1, 1), u_layer), 0);
  out_colour = 0.25 * sum;
}
