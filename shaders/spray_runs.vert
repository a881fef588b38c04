#version 450
// Runs of the spray layer's tiles (uv rectangles over the target, two triangles each): the passes
// after the particles draw only where there is spray.
#include "interface.glsl"
layout(std430, binding = RUNS_BUFFER) readonly buffer Runs {
  vec4 runs[];  // x0, y0, x1, y1
};
uniform float u_depth;  // the runs' depth: what the mask holds less than it is not drawn
out vec2 v_uv;
void main() {
  const int corners[6] = int[6](0, 1, 2, 2, 1, 3);
  vec4 run = runs[gl_VertexID / 6];
  int corner = corners[gl_VertexID % 6];
  vec2 p = vec2((corner & 1) != 0 ? run.z : run.x, (corner & 2) != 0 ? run.w : run.y);
  v_uv = p;
  gl_Position = vec4(p * 2.0 - 1.0, u_depth, 1.0);
}
