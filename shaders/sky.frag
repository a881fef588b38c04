#version 450
#include "common.glsl"
in vec3 v_ray;  // fullscreen_ray.vert
out vec4 out_colour;
void main() {
  vec3 dir = normalize(v_ray);
  vec3 sky = sky_gradient(dir);
  // A cloud deck at about 1.5 km, drifting with the wind; it thickens and greys with overcast.
  if (dir.z > 0.0) {
    vec2 p = frame.camera_pos.xy + dir.xy * (1500.0 / (dir.z + 0.08)) + frame.wind.xy * frame.time_s * 3.0;
    // Two octaves of value noise (2250 m and 119 m cells), the finer turned against the coarser,
    // so that no lattice's squares show; computed, not fetched (a fetch cost llvmpipe some 0.2 ms
    // of the sky at 640x360). The finer octave fades to its mean towards the horizon, where a
    // pixel spans more than its cells.
    const mat2 turn = mat2(0.80, 0.60, -0.60, 0.80);
    float fine = mix(0.5, value_noise(turn * p / 118.75), smoothstep(0.03, 0.12, dir.z));
    float n = value_noise(p / 2250.0) * 0.6 + fine * 0.4;
    float overcast = frame.overcast;
    float cover = smoothstep(0.75 - overcast * 0.8, 1.05 - overcast * 0.6, n);
    vec3 cloud_lit = mix(frame.sky_horizon.rgb * 1.15, frame.sky_horizon.rgb * 0.7, overcast * n) *
                     (1.0 - 0.2 * overcast);
    cloud_lit += frame.sun_radiance.rgb * 0.12;
    sky = mix(sky, cloud_lit, cover * smoothstep(0.0, 0.15, dir.z));
  }
  out_colour = vec4(to_display(sky), 1.0);
}
