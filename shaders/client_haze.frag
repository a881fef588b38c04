#version 450
// The server's haze over a client's picture (client_background_pass.hpp): the picture's light
// dimmed by the air between the camera and what it shows, and the sky's light scattered in
// (common.glsl's fog), by the picture's depth or the ground under the car; its sky stays as it is.
#include "common.glsl"
in vec2 v_uv;
in vec3 v_ray;  // fullscreen_ray.vert
out vec4 out_colour;
uniform vec3 u_forward;   // the picture's camera's axis (world, unit)
uniform vec4 u_ground;    // xyz the ground's unit normal (world), w the camera's height over it
uniform int u_has_depth;  // client_depth_tex holds the picture's depth, the view's reversed-Z
uniform float u_near;

void main() {
  vec3 seen = textureLod(client_image_tex, v_uv, 0.0).rgb;
  vec3 dir = normalize(v_ray);
  float along = 0.0;  // the distance along the ray; 0: the sky
  if (u_has_depth != 0) {
    float d = textureLod(client_depth_tex, v_uv, 0.0).r;
    along = d > 0.0 ? u_near / d / max(dot(dir, u_forward), 1e-3) : 0.0;
  } else {
    float down = -dot(dir, u_ground.xyz);
    along = down > 1e-4 ? u_ground.w / down : 0.0;
  }
  if (along > 0.0) seen = to_display(apply_fog(from_display(seen), fog_at(frame.camera_pos.xyz + dir * along)));
  out_colour = vec4(seen, 1.0);
}
