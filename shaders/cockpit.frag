#version 450
#include "common.glsl"
// The cabin, in the car's frame (cabin.vert), lit by the uniforms below rather than the frame
// block: CockpitPass gives them in the car's frame, rounded where it keeps the picture (llvmpipe),
// so that what a cached picture was drawn with is known exactly.
in vec3 v_world;  // the car's frame
in vec3 v_normal;
in vec2 v_uv;  // x material id (MATERIAL_*, interface.glsl)
in vec3 v_texture;  // where it reads model_tex: uv, layer (-1: none)
uniform float u_textured;  // 1 where the model has textures, else 0
uniform vec3 u_eye;           // the camera, car's frame
uniform vec3 u_up;            // the world's up, car's frame
uniform vec3 u_sun_dir;       // towards the sun, car's frame
uniform vec3 u_ambient;       // Atmosphere's
uniform vec3 u_sun_radiance;
uniform vec3 u_sky_horizon;
out vec4 out_colour;
void main() {
  vec3 n = normalize(v_normal);
  vec3 view = normalize(u_eye - v_world);
  n = dot(n, view) < 0.0 ? -n : n;
  // Dark plastic lit mostly by the sky through the glass: the silhouettes frame the view.
  vec3 albedo = int(v_uv.x + 0.5) == MATERIAL_BODY ? vec3(0.05) : trim_colour(v_uv.y, vec3(0.028, 0.028, 0.03));
  // A glTF cabin's base-colour texture times its colour (uniform control flow, as vehicle.frag).
  if (u_textured > 0.5)
    albedo *= mix(vec3(1.0), texture(model_tex, v_texture).rgb, step(-0.5, v_texture.z));
  vec3 light = u_ambient * (0.35 + 0.4 * max(dot(n, u_up), 0.0)) + u_sun_radiance * 0.15 * max(dot(n, u_sun_dir), 0.0);
  float sheen = schlick(dot(n, view), 0.03) * 0.3;
  out_colour = vec4(to_display(albedo * light + u_sky_horizon * sheen), 1.0);
}
