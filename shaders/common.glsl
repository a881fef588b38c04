// Shared by every scene shader: the per-frame uniform block and texture units (interface.glsl,
// generated from shader_interface.hpp), sky colour, fog and lighting.
#include "interface.glsl"
// Sky radiance along a world direction, without clouds. Kept free of pow(): on llvmpipe each
// pow is a log and an exp per channel, and this runs for every sky pixel.
vec3 sky_gradient(vec3 dir) {
  float up = clamp(dir.z, 0.0, 1.0);
  vec3 sky = mix(frame.sky_horizon.rgb, frame.sky_zenith.rgb, sqrt(up));
  // Below the horizon: the horizon colour, a little darker (distant ground under haze).
  sky = dir.z < 0.0 ? frame.sky_horizon.rgb * (1.0 - 0.15 * clamp(-dir.z * 4.0, 0.0, 1.0)) : sky;
  float sun = max(dot(dir, frame.sun_dir.xyz), 0.0);
  float s2 = sun * sun, s4 = s2 * s2, s8 = s4 * s4;
  float disc = smoothstep(0.9990, 0.9996, sun) * (1.0 - frame.params.y);
  sky += frame.sun_radiance.rgb * (0.25 * s8 * s4 + 0.3 * disc);
  return sky;
}

// Haze, per vertex (mesh.vert): rgb the light scattered in along the way, a the transmittance.
vec4 fog_at(vec3 world_pos) {
  vec3 to = world_pos - frame.camera_pos.xyz;
  float dist = length(to);
  return vec4(sky_gradient(to / max(dist, 1e-3)), exp(-frame.fog.a * dist));
}

vec3 apply_fog(vec3 colour, vec4 fog) { return mix(fog.rgb, colour, fog.a); }

// Diffuse light from the sun and the sky dome on a surface with normal n, the sun's share times
// sun_lit (a shadow's 0 .. 1).
vec3 diffuse_light_shadowed(vec3 n, float sun_lit) {
  float ndl = max(dot(n, frame.sun_dir.xyz), 0.0);
  float sky_view = 0.55 + 0.45 * n.z;
  return frame.sun_radiance.rgb * (ndl * sun_lit) + frame.ambient.rgb * sky_view;
}
vec3 diffuse_light(vec3 n) { return diffuse_light_shadowed(n, 1.0); }

// Schlick's Fresnel approximation.
float schlick(float cos_theta, float r0) {
  float m = 1.0 - clamp(cos_theta, 0.0, 1.0);
  float m2 = m * m;
  return r0 + (1.0 - r0) * m2 * m2 * m;
}

// Display transform: a gentle shoulder, then gamma 2 (sqrt: far cheaper than pow on llvmpipe).
vec3 to_display(vec3 c) {
  c = c / (1.0 + 0.15 * c);
  return sqrt(clamp(c, 0.0, 1.0));
}
