// Shared by every scene shader: the per-frame uniform block and texture units (interface.glsl,
// generated from shader_interface.hpp), sky colour, fog and lighting.
#include "interface.glsl"
// Sky radiance along a world direction, without clouds. Kept free of pow(): on llvmpipe each
// pow is a log and an exp per channel, and this runs for every sky pixel.
vec3 sky_gradient(vec3 dir) {
  float up = clamp(dir.z, 0.0, 1.0), rise = sqrt(up);
  vec3 sky = mix(frame.sky_horizon.rgb, frame.sky_zenith.rgb, rise);
  // The clear sky's scattering by the sun's place (sky_table.hpp): what it adds to the gradient.
  vec2 sun_xy = frame.sun_dir.xy;
  float toward = dot(dir.xy, sun_xy) *
                 inversesqrt(max(dot(dir.xy, dir.xy) * dot(sun_xy, sun_xy), 1e-12));
  const vec2 size = vec2(SKY_TABLE_WIDTH, SKY_TABLE_HEIGHT);
  vec2 at = vec2(0.5 - 0.5 * toward, rise) * ((size - 1.0) / size) + 0.5 / size;
  sky = max(sky + textureLod(sky_tex, at, 0.0).rgb, 0.0);
  // Below the horizon: the horizon's colour, a little darker (distant ground under haze).
  sky *= 1.0 - 0.15 * clamp(-dir.z * 4.0, 0.0, 1.0);
  float sun = max(dot(dir, frame.sun_dir.xyz), 0.0);
  float s2 = sun * sun, s4 = s2 * s2, s8 = s4 * s4;
  float disc = smoothstep(0.9990, 0.9996, sun) * (1.0 - frame.overcast);
  sky += frame.sun_radiance.rgb * (0.25 * s8 * s4 + 0.3 * disc);
  return sky;
}

// Value noise on a lattice of unit cells: a hash's value in [0, 1] at each corner, quintic
// between them, as noise_tex's channels hold it, but computed: on llvmpipe a filtered fetch over
// a view's road or sky costs some 0.2-0.5 ms, these few integer operations next to nothing.
float value_noise(vec2 p) {
  vec2 i = floor(p), f = p - i;
  vec2 u = f * f * f * (f * (f * 6.0 - 15.0) + 10.0);
  // The corners' hash: the lattice point's coordinates mixed (multiply, xor-shift, multiply).
  uvec2 c = uvec2(ivec2(i)) * uvec2(0x8da6b343u, 0xd8163841u);
  uvec2 d = c + uvec2(0x8da6b343u, 0xd8163841u);
  uvec4 h = uvec4(c.x, d.x, c.x, d.x) + uvec4(c.y, c.y, d.y, d.y);
  h = (h ^ (h >> 16u)) * 0x7feb352du;
  h = (h ^ (h >> 15u)) * 0x846ca68bu;
  vec4 v = vec4(h >> 8u) * (1.0 / 16777215.0);
  return mix(mix(v.x, v.y, u.x), mix(v.z, v.w, u.x), u.y);
}
// The same where a pixel spans `cells` of its cells (length(fwidth(p))): toward its mean, 0.5, as
// that goes from half a cell to two, as mipmaps would average it away.
float value_noise_filtered(vec2 p, float cells) {
  return mix(0.5, value_noise(p), clamp((2.0 - cells) * (1.0 / 1.5), 0.0, 1.0));
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

// Lamp i's illuminance (lux, rgb) at p on a surface with normal n (the lamp block,
// shader_interface.hpp): its intensity across its cones, over the distance squared. A dipped
// beam (right-hand traffic) gives no light above 0.6 degrees under the horizon towards the
// oncoming lanes, its cut-off rising at 15 degrees on the nearside.
vec3 lamp_lux(int i, vec3 p, vec3 n) {
  vec4 at = lamps.lamp[4 * i], axis = lamps.lamp[4 * i + 1];
  vec4 cd = lamps.lamp[4 * i + 2], shape = lamps.lamp[4 * i + 3];
  vec3 to = p - at.xyz;
  float d2 = max(dot(to, to), 0.25);
  vec3 l = to * inversesqrt(d2);
  float beam = smoothstep(axis.w, cd.w, dot(l, axis.xyz));
  float limit = -0.0105 + 0.268 * max(-dot(l.xy, shape.yz), 0.0);
  beam *= mix(1.0, smoothstep(limit + 0.006, limit - 0.006, l.z), shape.x);
  return cd.rgb * (beam * max(dot(n, -l), 0.0) / d2);
}

// The lamps' light on an upward surface at p, as radiance per unit albedo: the lamp map's fine
// ring where it holds p (fading over its last 4 cells), else its coarse one (lamp_map.hpp).
vec3 lamp_ground(vec3 p) {
#ifdef NO_LAMPS
  return vec3(0.0);
#else
  // Without a lamp map (by day) the same for every pixel. (llvmpipe still fetches: a program
  // compiled with NO_LAMPS, where a frame has no lamps, does not.)
  if (frame.lamp_map.x < 0.5) return vec3(0.0);
  vec4 r0 = frame.lamp_rings[0], r1 = frame.lamp_rings[1];
  vec2 uv0 = (p.xy - r0.xy) * r0.z, uv1 = (p.xy - r1.xy) * r1.z;
  vec2 e0 = min(uv0, 1.0 - uv0), e1 = min(uv1, 1.0 - uv1);
  float in0 = clamp(min(e0.x, e0.y) * 32.0, 0.0, 1.0);
  float in1 = clamp(min(e1.x, e1.y) * 32.0, 0.0, 1.0);
  vec3 fine = texture(lamp_map_tex, vec3(uv0, 0.0)).rgb;
  vec3 coarse = texture(lamp_map_tex, vec3(uv1, 1.0)).rgb;
  return mix(coarse * in1, fine, in0);
#endif
}

// The lamps' light that water in the air at p scatters towards the eye (to_eye: unit, from p):
// the ego car's beams and the two lamps after them in the lamp block (the nearest ahead), through
// a drop's rough phase function, as rain_layer.cpp's (much forwards, some back, little sideways);
// as radiance.
vec3 lamps_scattered(vec3 p, vec3 to_eye) {
  vec3 e = vec3(0.0);
#ifdef NO_LAMPS
  return e;
#endif
  int n = min(int(lamps.count.y), int(lamps.count.x) + 2);
  for (int i = 0; i < n; ++i) {
    vec3 from_lamp = normalize(p - lamps.lamp[4 * i].xyz);
    float c = dot(from_lamp, to_eye);
    float fwd = max(c, 0.0), back = max(-c, 0.0);
    float f2 = fwd * fwd, f4 = f2 * f2;
    e += lamp_lux(i, p, -from_lamp) * (0.06 + 0.3 * back * back + 2.0 * f4 * f4);
  }
  return e * frame.lamp_map.y;
}

// The ego car's headlights on a surface at p with normal n, per pixel (the first lamps of the
// block), as radiance per unit albedo.
vec3 ego_headlights(vec3 p, vec3 n) {
  vec3 e = vec3(0.0);
#ifdef NO_LAMPS
  return e;
#endif
  int ego = int(lamps.count.x);
  for (int i = 0; i < ego; ++i) e += lamp_lux(i, p, n);
  return e * frame.lamp_map.y;
}

// Schlick's Fresnel approximation.
float schlick(float cos_theta, float r0) {
  float m = 1.0 - clamp(cos_theta, 0.0, 1.0);
  float m2 = m * m;
  return r0 + (1.0 - r0) * m2 * m2 * m;
}

// Fresnel's reflectance of unpolarized light on water (n = 1.333) from air, exact: Schlick's
// approximation gives a tenth less between 50 and 70 degrees from the normal, where a road is seen
// from a driver's or a chase camera's height, and more at grazing angles.
float fresnel_water(float cos_theta) {
  float c = clamp(cos_theta, 1e-4, 1.0);
  float g = sqrt(0.7769 + c * c);  // sqrt(n^2 - 1 + c^2)
  float a = (g - c) / (g + c);
  float b = (c * (g + c) - 1.0) / (c * (g - c) + 1.0);
  return 0.5 * a * a * (1.0 + b * b);
}

// What a glossy surface on the road (a car's paint, its windows) sees along dir: the sky above the
// horizon; below it the road, a few metres off: its asphalt in the sun's and the sky's light
// (darker wet), and over it the sky the road mirrors (Fresnel's term for rough asphalt dry, for
// water as it wets), which at the horizon is the sky itself. Not the bright haze of distant ground
// that sky_gradient gives there: a car's lower panels, and its rear seen from a camera above it,
// show the road in their sheen. (Seen from below, in the road's mirror, the rear shows the sky.)
vec3 surroundings(vec3 dir) {
  vec3 sky = sky_gradient(vec3(dir.xy, abs(dir.z)));
  float down = max(-dir.z, 0.0);
  float f = mix(schlick(down, 0.02), fresnel_water(down), frame.wetness);
  vec3 ground = vec3(mix(0.1, 0.05, frame.wetness)) * diffuse_light(vec3(0.0, 0.0, 1.0));
  return mix(sky, mix(ground, sky, f), step(0.0, -dir.z));
}

// The light a cloud of droplets (the spray's haze) sends towards the eye where the screen's uv sees
// it at distance z along the view's axis: the droplets' light from the sky and the scene (`light`,
// linear) and the lamps' where their beams pass through the cloud's point. The frame's camera: the
// view's, or the road mirror's (its rays, unfolded at the road, run through the real world).
vec3 haze_radiance(vec2 uv, float z, vec3 light) {
  vec4 far = frame.inv_view_proj * vec4(uv * 2.0 - 1.0, 0.5, 1.0);
  vec4 centre = frame.inv_view_proj * vec4(0.0, 0.0, 0.5, 1.0);
  vec3 dir = normalize(far.xyz / far.w - frame.camera_pos.xyz);
  vec3 ahead = normalize(centre.xyz / centre.w - frame.camera_pos.xyz);
  vec3 p = frame.camera_pos.xyz + dir * (z / max(dot(dir, ahead), 0.1));
  return light + lamps_scattered(p, -dir);
}

// Display transform: a gentle shoulder, then gamma 2 (sqrt: far cheaper than pow on llvmpipe).
vec3 to_display(vec3 c) {
  c = c / (1.0 + 0.15 * c);
  return sqrt(clamp(c, 0.0, 1.0));
}
// Its inverse: the radiance a display-encoded colour stands for (up to the shoulder's 1.18).
vec3 from_display(vec3 d) {
  vec3 c = d * d;
  return c / max(1.0 - 0.15 * c, 0.05);
}

// A trim colour a model carries in uv.y (model/vehicle_model.hpp's pack_trim_colour): 0 none (the
// given colour), else 1 + 5 bits each of linear red, green and blue.
vec3 trim_colour(float code, vec3 otherwise) {
  int c = int(code + 0.5) - 1;
  return c < 0 ? otherwise : vec3((c >> 10) & 31, (c >> 5) & 31, c & 31) / 31.0;
}
