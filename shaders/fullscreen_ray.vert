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
  // far_point / w less the camera, times w, which keeps it linear. A perspective's inverse gives
  // every point of one depth the same w (positive for the views', the mirror's and the
  // environment's cameras); its sign is taken out all the same.
  v_ray = (far_point.xyz - frame.camera_pos.xyz * far_point.w) * sign(far_point.w);
  gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
  // The road's mirror draws the sky with its plane's clip distance enabled: nothing of the sky is
  // cut (a distance enabled and not written is undefined).
  gl_ClipDistance[0] = 1.0;
}
