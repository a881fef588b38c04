#version 450
// The rain layer's runs of tiles with rain (rain_layer.hpp), two triangles each, at the depth of a
// plane over the view. The runs the cabin reaches into are drawn depth-tested with the plane the
// windshield's, so that the test keeps the rain off what is on the driver's side of the glass
// without a depth per pixel, and with depth clamping, so that no part of a run is clipped where
// the plane leaves [0, 1]. The others are drawn without a depth test.
#include "interface.glsl"
layout(std430, binding = RUNS_BUFFER) readonly buffer Runs {
  vec4 runs[];  // uv over the view: x0, y0, x1, y1
};
out vec2 v_uv;
uniform vec3 u_plane_depth;  // reversed-Z depth over the view: dot(xyz, (uv, 1))
void main() {
  const int corners[6] = int[6](0, 1, 2, 2, 1, 3);
  vec4 run = runs[gl_VertexID / 6];
  int corner = corners[gl_VertexID % 6];
  vec2 p = vec2((corner & 1) != 0 ? run.z : run.x, (corner & 2) != 0 ? run.w : run.y);
  v_uv = p;
  gl_Position = vec4(p * 2.0 - 1.0, dot(u_plane_depth, vec3(p, 1.0)), 1.0);
}
