#version 450
#include "common.glsl"
in vec3 v_world;
in vec3 v_normal;
in vec2 v_uv;  // x lateral offset (m, left positive), y distance along the track (m)
in vec4 v_fog;
out vec4 out_colour;

uniform float u_lane_width;
uniform int u_lanes_each_way;
uniform float u_paved_half_width;

const float kReliefTile = 1.5;  // metres of road per repeat of the relief texture

// Coverage of a painted stripe of half width hw centred at c, antialiased over one pixel.
float stripe(float x, float c, float hw) {
  float w = max(fwidth(x), 1e-4);
  return clamp((hw - abs(x - c)) / w + 0.5, 0.0, 1.0);
}

void main() {
  float lat = v_uv.x;
  float s = v_uv.y;
  float a = abs(lat);
  float lanes = u_lane_width * float(u_lanes_each_way);

  // Surface frame: normal from the mesh, tangent along the track from the uv derivatives.
  vec3 n_geo = normalize(v_normal);
  vec3 dp_dx = dFdx(v_world), dp_dy = dFdy(v_world);
  vec2 duv_dx = dFdx(v_uv), duv_dy = dFdy(v_uv);
  vec3 t_along = dp_dx * duv_dy.x - dp_dy * duv_dx.x;  // direction of growing s
  t_along = normalize(t_along - n_geo * dot(n_geo, t_along) + 1e-6);
  vec3 t_lat = cross(n_geo, t_along);

  vec4 relief = texture(asphalt_tex, vec2(lat, s) / kReliefTile);
  // Fade the relief with distance, where its texels get smaller than a pixel.
  float detail = clamp(1.5 - length(fwidth(v_uv)) * 6.0, 0.0, 1.0);
  vec3 rn = relief.rgb * 2.0 - 1.0;
  vec3 n = normalize(mix(n_geo, normalize(t_lat * rn.x + t_along * rn.y + n_geo * rn.z), detail));

  // Asphalt: light aggregate in dark binder; worn, darker wheel paths; patches.
  float h = relief.a;
  float patches = texture(noise_tex, vec2(lat, s) / 40.0).g;
  vec3 albedo = vec3(mix(0.055, 0.16, smoothstep(0.15, 0.8, h))) * (0.85 + 0.3 * patches);
  float lane_pos = fract(a / u_lane_width);
  float wheel_paths = stripe(lane_pos, 0.27, 0.09) + stripe(lane_pos, 0.73, 0.09);
  albedo *= 1.0 - 0.18 * clamp(wheel_paths, 0.0, 1.0) * step(a, lanes);

  // Markings: double centre line, dashed lane dividers (3 m on, 9 m off), solid edge lines.
  float paint = stripe(a, 0.2, 0.07);
  for (int i = 1; i < u_lanes_each_way; ++i) {
    paint += stripe(a, u_lane_width * float(i), 0.075) * step(fract(s / 12.0), 0.25);
  }
  paint += stripe(a, lanes + 0.2, 0.1);
  paint = clamp(paint, 0.0, 1.0);
  albedo = mix(albedo, vec3(0.72, 0.72, 0.68), paint);
  n = normalize(mix(n, n_geo, paint * 0.8));  // paint fills the relief

  // Beyond the pavement: gravel verge, then grass.
  float verge = smoothstep(u_paved_half_width, u_paved_half_width + 0.05, a);
  vec3 gravel = vec3(0.16, 0.15, 0.13) * (0.7 + 0.6 * h);
  vec3 grass = vec3(0.11, 0.16, 0.06) * (0.8 + 0.4 * patches);
  albedo = mix(albedo, mix(gravel, grass, smoothstep(u_paved_half_width + 1.0, u_paved_half_width + 2.5, a)), verge);

  // Wetness darkens the diffuse part and adds a sky reflection (Fresnel) on the smoother water film.
  float wet = frame.params.z * (1.0 - verge * 0.5);
  albedo *= mix(1.0, 0.55, wet);
  vec3 view = normalize(frame.camera_pos.xyz - v_world);
  vec3 colour = albedo * diffuse_light(n);
  vec3 n_film = normalize(mix(n, n_geo, 0.7 * wet));
  float fresnel = schlick(dot(n_film, view), 0.02);
  vec3 refl = sky_gradient(reflect(-view, n_film));
  colour += refl * fresnel * (0.25 + 0.75 * wet);
  out_colour = vec4(to_display(apply_fog(colour, v_fog)), 1.0);
}
