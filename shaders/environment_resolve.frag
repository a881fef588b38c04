#version 450
// An environment probe's face (environment_probe.hpp) made linear radiance: the world as the
// passes drew it, its display transform undone, and the sun's disc at its energy where the sky
// shows: a spot a texel or so wide whose light, summed over it, is the sun's irradiance.
#include "common.glsl"
in vec2 v_uv;
out vec4 out_colour;
uniform mat4 u_face;        // columns: the face's right, up and forward (world)
uniform float u_texel_rad;  // a texel's angle at the face's centre
uniform vec3 u_sun_energy;  // the sun's irradiance, as pi times the radiance a white card shows
void main() {
  vec3 seen = from_display(textureLod(view_colour_tex, v_uv, 0.0).rgb);
  vec2 xy = v_uv * 2.0 - 1.0;
  vec3 dir = normalize(mat3(u_face) * vec3(xy, 1.0));
  // The disc (a quarter of a degree in radius) as a spot no narrower than a texel.
  float sigma = max(u_texel_rad, 0.0047);
  float a2 = 2.0 * max(1.0 - dot(dir, frame.sun_dir.xyz), 0.0);  // angle squared
  float sky = textureLod(view_depth_tex, v_uv, 0.0).r == 0.0 ? 1.0 : 0.0;  // nothing drawn there
  vec3 sun = u_sun_energy * (sky * exp(-0.5 * a2 / (sigma * sigma)) / (6.2831853 * sigma * sigma));
  out_colour = vec4(seen + sun, 1.0);
}
