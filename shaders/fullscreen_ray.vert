#version 450
// fullscreen.vert's triangle over the viewport, with each corner's view ray in world axes: the ray
// through a pixel is linear in its place on the screen (the frame's camera, through the far plane),
// so a fragment takes its ray interpolated and only normalizes it. Worked out per pixel from the
// inverse projection, the same ray cost llvmpipe 1-4 ms of a 1280x720 view's CPU in the sky alone.
#include "common.glsl"
out vec2 v_uv;
out vec3 v_ray;  // towards what the pixel sees, not unit
void main() {
  vec2 p = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2);
  v_uv = p;
  vec4 far_point = frame.inv_view_proj * vec4(p * 2.0 - 1.0, 1e-6, 1.0);
  // far_point / w less the camera, times w, which keeps it linear; w's sign taken out.
  v_ray = (far_point.xyz - frame.camera_pos.xyz * far_point.w) * sign(far_point.w);
  gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}
