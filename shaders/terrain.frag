#version 450
#include "common.glsl"
in vec3 v_world;
in vec3 v_normal;
in vec2 v_uv;
in vec4 v_fog;
out vec4 out_colour;
void main() {
  vec3 n = normalize(v_normal);
  // Grass with patches of drier grass and soil, rock on steep slopes.
  float large = value_noise(v_uv / 150.0);
  float medium = value_noise_filtered(v_uv / 18.75, length(fwidth(v_uv)) / 18.75);
  float fine = texture(noise_tex, v_uv / 6.0).a;  // 19 cm cells, their mipmaps further off
  vec3 grass = mix(vec3(0.09, 0.15, 0.05), vec3(0.20, 0.22, 0.09), large);
  grass = mix(grass, vec3(0.17, 0.14, 0.09), smoothstep(0.55, 0.8, medium) * 0.6);
  grass *= 0.8 + 0.4 * fine;
  vec3 rock = vec3(0.22, 0.21, 0.2) * (0.8 + 0.4 * fine);
  vec3 albedo = mix(grass, rock, smoothstep(0.82, 0.7, n.z));
  albedo *= mix(1.0, 0.75, frame.wetness);  // wet ground is darker
  vec3 colour = albedo * (diffuse_light(n) + lamp_ground(v_world) * max(n.z, 0.0));
  out_colour = vec4(to_display(apply_fog(colour, v_fog)), 1.0);
}
