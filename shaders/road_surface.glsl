// The road surface, included by its three programs (road_pass.cpp picks one per frame, since
// llvmpipe pays for both sides of a branch on every pixel): road.frag without a mirror (a dry or
// only wet road), road_mirror.frag with the road reflection (a film stands somewhere), and
// road_ripples.frag with the reflection and the rings of drops in puddles (puddles in the rain);
// each of them also with the relief's shadows under the sun (ROAD_RELIEF, the *_relief.frag ones).
#include "common.glsl"
in vec3 v_world;
in vec3 v_normal;
in vec2 v_uv;  // x lateral offset (m, left positive), y distance along the track (m)
in vec4 v_fog;
out vec4 out_colour;

// Its strip among the road's lanes (mesh_data.hpp's VertexLane): its right border's t, its width
// (+ 100 on a lane cars drive in; +-1000 on a verge, whose t is the paved edge's), and the marks
// on its borders, packed. (Flat: one varying, where llvmpipe pays for every one on every pixel.)
flat in vec4 v_strip;

const float kReliefTile = 1.5;  // metres of road per repeat of the asphalt's relief (relief.hpp)
const float kSettsTile = 1.0;   // the setts' (relief.hpp)
const float kGroundTile = 3.0;  // of both in ground_relief_tex (relief.hpp's kGroundTileM)
const float kSettsWidth = 1.0;  // the band of setts from the pavement's edge out

// The sunlight the asphalt's and the setts' relief keep past their shadows, over many texels
// (relief.hpp's mean_lit): every program's where a pixel covers many texels; (1, 1) without them.
uniform vec2 u_relief_mean_lit;

#ifdef ROAD_RELIEF
in vec2 v_curvature;       // k1, k2 (1/m, convex positive)
in vec4 v_principal_dirs;  // v1, v2 in (u, v)
uniform int u_horizon_directions;  // a relief's layers in horizon_tex
uniform vec2 u_relief_depth_m;     // the asphalt's and the setts' heights for a texture's 1
const float kHorizonDistanceRange = 0.5;  // m (relief.hpp)

// Relief shadows on a curved surface (seed 002). l: the light in the texture's frame (x along u,
// y along v, z the normal); tex: the relief's texture coordinates, layer0 its first layer in
// horizon_tex; h the texel's height over the surface (m). 1 lit, 0 in the shadow.
float relief_lit(vec3 l, vec2 tex, float layer0, float h) {
  float along = length(l.xy);
  float tan_theta = l.z / max(along, 1e-4);
  // The two layers nearest the light's azimuth, linear between them.
  float n = float(u_horizon_directions);
  float f = atan(l.y, l.x) * (n / 6.2831853);
  f = f < 0.0 ? f + n : f;
  float k0 = min(floor(f), n - 1.0);
  // Layer k0 holds azimuths k0 and k0 + 1, 8 bits each (relief.hpp's packed_layer).
  vec4 maps = texture(horizon_tex, vec3(tex, layer0 + k0));
  vec4 x = maps * 2.0 - 1.0;
  vec2 tans = 4.0 * x.xz * abs(x.xz);
  vec2 dists = maps.yw * maps.yw * kHorizonDistanceRange;
  vec2 horizon = mix(vec2(tans.x, dists.x), vec2(tans.y, dists.y), f - k0);
  // Eq. 1: the curvature along the light, k1 cos^2 + k2 sin^2 (squares only); convex parts alone.
  vec2 v1 = v_principal_dirs.xy, v2 = v_principal_dirs.zw;
  float c = dot(l.xy, v1), s = dot(l.xy, v2);
  float k = (v_curvature.x * c * c / max(dot(v1, v1), 1e-6) +
             v_curvature.y * s * s / max(dot(v2, v2), 1e-6)) / max(along * along, 1e-8);
  k = max(k, 0.0);
  // Eq. 2, the horizon point sunk by the curve; eq. 3, the surface's own rim below the tangent
  // plane; the higher one holds (relief.hpp's corrected_tan_horizon).
  float on_relief = horizon.r * (1.0 - k * h) - 0.5 * k * horizon.g;
  float rim = 1.0 / (k * h + 1.0);
  float on_surface = -sqrt(max(1.0 - rim * rim, 0.0)) / rim;
  float tan_beta = max(on_relief, on_surface);
  // A soft edge: the penumbra of the sun's half degree, and the maps' filtering.
  return smoothstep(-0.015, 0.015, tan_theta - tan_beta);
}
#endif

// Coverage of a painted stripe of half width hw centred at c, antialiased over one pixel.
float stripe(float x, float c, float hw) {
  float w = max(fwidth(x), 1e-4);
  return clamp((hw - abs(x - c)) / w + 0.5, 0.0, 1.0);
}

// A lane border's mark (mesh_data.hpp's pack_lane_mark) at u across from the border (m), w a
// pixel's width in u, dash 1 where a broken line is painted. Of a double line, only the line on
// u's side counts (they are apart). (x paint, y its yellow part.)
vec2 lane_mark(float mark, float u, float w, float dash) {
  int code = int(mark);
  float kind = float(code & 7);
  vec4 m = vec4(float(code & 8), float((code >> 4) & 63) * 0.01,
                float(((code >> 10) & 127) - 64) * 0.01, float((code >> 17) & 127) * 0.01);
  float c = m.b;
  // Single lines: 1 solid, 2 broken; double lines, right then left: 3 solid solid, 4 solid broken,
  // 5 broken solid, 6 broken broken.
  float double_line = step(2.5, kind);
  float right = step(u, c);
  c += double_line * (0.5 - right) * m.a;
  float solid = kind == 1.0 || kind == 3.0 || (right > 0.5 ? kind == 4.0 : kind == 5.0) ? 1.0 : 0.0;
  float p = step(0.5, kind) * mix(dash, 1.0, solid) *
            clamp((0.5 * m.g - abs(u - c)) / w + 0.5, 0.0, 1.0);
  return vec2(p, p * step(8.0, m.r));  // (m.r: 8 if yellow)
}

// The water at xy: x all of it (mm), y the part standing above the texture (mm). From the finest
// of the water's rings that holds it, each ring fading out over its last 4 cells to the coarser one
// under it (whose cells there hold the finer ones' means), the last one to the rings' mean; without
// rings, the weather's wetness alone. A ring's fading band lies well inside the next ring (twice
// its size), so a point takes at most two rings: the finest that holds it and the next. Both are
// found from the point's distance to the rings' middle, then fetched once each: llvmpipe runs a
// loop that ends pixel by pixel, masked, until its last pixel is done (2 ms of ROAD's road pass),
// and a loop over every ring, the same for all pixels, cost 0.9 ms.
vec2 water_at(vec2 xy) {
  float wet = frame.wetness;
  if (frame.road_water_state.w == 0.0) return vec2(wet * 0.5, wet * wet * 0.15);
  int rings = int(frame.road_water.x);
  // The finest ring that may hold xy, by its distance from ring 0's middle (along x or y), and
  // the next: where xy lies outside the first, it lies past the second's fading band (windows of
  // 64 cells or more, RoadWaterConfig).
  vec4 r0 = frame.road_water_rings[0];
  vec2 off = abs(xy - r0.xy - 0.5 / r0.z);
  float l = dot(step(frame.road_water_reach, vec4(max(off.x, off.y))), vec4(1.0));
  int li = min(int(l), 3);
  // (Chosen, not indexed: llvmpipe would gather an indexed uniform lane by lane.)
  vec4 r1 = frame.road_water_rings[1], r2 = frame.road_water_rings[2], r3 = frame.road_water_rings[3];
  vec4 ring = li == 0 ? r0 : li == 1 ? r1 : li == 2 ? r2 : r3;
  vec4 next = li == 0 ? r1 : li == 1 ? r2 : r3;
  vec2 uv = (xy - ring.xy) * ring.z;
  vec2 next_uv = (xy - next.xy) * next.z;
  vec2 edge = min(uv, 1.0 - uv);
  float inside = clamp(min(edge.x, edge.y) * frame.road_water.y, 0.0, 1.0);
  float none = float(rings);
  float layer = l < none ? l : none, next_layer = l + 1.0 < none ? l + 1.0 : none;
  vec2 mean = frame.road_water_state.yz;
  vec2 fine = layer < none ? texture(road_water_tex, vec3(uv, layer)).rg : mean;
  vec2 coarse = next_layer < none ? texture(road_water_tex, vec3(next_uv, next_layer)).rg : mean;
  return mix(coarse, fine, inside);
}

#ifdef ROAD_RIPPLES
uint hash_u(uint x) {
  x ^= x >> 16; x *= 0x7feb352du; x ^= x >> 15; x *= 0x846ca68bu; x ^= x >> 16;
  return x;
}
vec3 hash3(ivec2 cell, int cycle) {
  uint h = hash_u(uint(cell.x) * 0x9e3779b9u ^ hash_u(uint(cell.y) + uint(cycle) * 0x85ebca6bu));
  uvec3 b = uvec3(h, h >> 11, h >> 22) & uvec3(2047u, 2047u, 1023u);
  return vec3(b) / vec3(2047.0, 2047.0, 1023.0);
}

// Ripples (seed 004): every drop that lands in a puddle starts a ring that grows toward the
// puddle's size while it sinks and fades. Each 0.35 m cell of the world's grid holds one drop per
// life of a ring, landing at a random point, with a probability that follows the rain rate (up to
// about 9 rings per m^2 and second from 25 mm/h). A pixel sums the rings of its 2 x 2 nearest
// cells; returns the slope they give the water (world xy).
const float kRippleCell = 0.35;
const float kRippleLife = 0.9;  // s
vec3 ripple_slope(vec2 xy, float standing_mm) {
  float chance = clamp(frame.rain_rate_mm_h / 25.0, 0.0, 1.0);
  if (chance <= 0.0) return vec3(0.0);
  // Rings reach a cell's half in a deep puddle, less in a shallow one.
  float reach = kRippleCell * 0.5 * clamp(standing_mm / 4.0, 0.35, 1.0);
  vec2 g = xy / kRippleCell;
  ivec2 base = ivec2(floor(g - 0.5));
  vec2 slope = vec2(0.0);
  // (A loop that no pixel of a block outside the puddles enters: llvmpipe skips it there, where
  // an if would run for every pixel.)
  int cells = standing_mm > 0.6 ? 4 : 0;
  for (int k = 0; k < cells; ++k) {
    ivec2 cell = base + ivec2(k & 1, k >> 1);
    vec3 h0 = hash3(cell, 0);
    float phase = frame.time_s / kRippleLife + h0.z;
    int cycle = int(floor(phase));
    float age = phase - float(cycle);
    vec3 h = hash3(cell, cycle + 1);
    vec2 centre = (vec2(cell) + 0.2 + 0.6 * h.xy) * kRippleCell;
    vec2 d = xy - centre;
    float dist = length(d) + 1e-4;
    float x = (dist - age * reach) * (1.0 / 0.025);
    // A ring of two crests, sinking and fading with age; none where the cycle's drop did not fall.
    float fade = (1.0 - age) * (1.0 - age) * step(h.z, chance);
    float wave = x * exp(-x * x) * fade;
    slope += d / dist * wave;
  }
  return vec3(-slope * 0.8, 0.0);
}
#endif

#ifdef ROAD_MIRROR
// What the ray r from p on the road sees in the quarter-size mirror (`sky` where it sees none):
// where the mirror image of the pixel lies (its depth), how far along r that is, and where that
// point's mirror image falls.
// On the mirror's plane with its normal this is the pixel itself; a surface on a crest or in a
// dip, tilted by the crown or moved by ripples, looks up its own reflection. The sky beyond the
// mirror's edges.
// The nearest lamps' glints on the water (after the ego car's headlights, whose light goes away
// from its own eye, the lamp block's next kGlintLamps, ahead of the camera nearest first): the
// mirror at a quarter of the view's size keeps a lamp as a dot at most, where a wet road at night
// shows it as a long streak down towards the viewer. A microfacet lobe, the lamp's illuminance E
// times D(h) / (4 n.v), as radiance (times pi and the exposure, as a lens's luminance shows); the
// caller applies the Fresnel term. D is anisotropic, as the ripples and the texture's peaks tilt
// the water more along the view than across it: (1 - (a / 0.05)^2 - (b / 0.16)^2)^8 for the half
// vector's tilts a across and b along the view, normalized (pi 0.05 0.16 / 9 of the hemisphere).
const int kGlintLamps = 4;
vec3 lamp_glints(vec3 p, vec3 n, vec3 view) {
  vec3 across = normalize(cross(n, view) + vec3(1e-5, 0.0, 0.0));
  vec3 along = cross(across, n);
  vec3 s = vec3(0.0);
  int first = int(lamps.count.x), last = min(first + kGlintLamps, int(lamps.count.y));
  for (int i = first; i < last; ++i) {
    vec4 at = lamps.lamp[4 * i], axis = lamps.lamp[4 * i + 1], cd = lamps.lamp[4 * i + 2];
    vec3 to = at.xyz - p;
    float d2 = max(dot(to, to), 0.25);
    vec3 l = to * inversesqrt(d2);
    float beam = smoothstep(axis.w, cd.w, -dot(l, axis.xyz)) * step(0.0, dot(n, l));
    vec3 h = normalize(l + view);
    float a = dot(h, across), b = dot(h, along);
    float x = max(1.0 - a * a * 400.0 - b * b * 40.0, 0.0);
    float x2 = x * x, x4 = x2 * x2;
    s += cd.rgb * (beam * x4 * x4 / d2);
  }
  return s * (frame.lamp_map.y * 3.14159 * 362.0 / (4.0 * max(dot(n, view), 0.1)));
}

vec3 mirrored(vec3 p, vec3 r, vec3 sky, float streak) {
  vec4 clip = frame.view_proj * vec4(p, 1.0);
  vec2 uv0 = clip.xy / clip.w * 0.5 + 0.5;
  float d = textureLod(reflection_depth_tex, uv0, 0.0).r;
  // Reversed-Z with an infinite far plane: depth = near / distance along the view axis, and
  // clip.z is the near distance for every point.
  float a = d * clip.w;
  float b = length(p - frame.camera_pos.xyz) * max(clip.z - a, 0.0);
  vec4 c = frame.mirror_view_proj * vec4(p * a + r * b, a);
  if (c.w <= 1e-5) return sky;
  vec2 uv = c.xy / c.w * 0.5 + 0.5;
  vec2 inside = clamp(min(uv, 1.0 - uv) * 20.0, 0.0, 1.0);
  // A streak on a film: two taps along the image's vertical, a 60th of the view's height apart
  // (half a degree either side in a 60-degree view): the film's slopes spread the mirror by an
  // angle, the same at every size of the view. The taps are light, so they add in linear light
  // (the mirror holds display values).
  vec2 dv = vec2(0.0, streak / 120.0);
  vec3 seen = (from_display(textureLod(reflection_tex, uv - dv, 0.0).rgb) +
               from_display(textureLod(reflection_tex, uv + dv, 0.0).rgb)) * 0.5;
  return mix(sky, seen, inside.x * inside.y);
}
#endif

void main() {
  float lat = v_uv.x;
  float s = v_uv.y;
  // How far beyond the paved edge (0 on the pavement), and where across its lane.
  float on_verge = step(999.0, abs(v_strip.y));
  float driving = step(99.5, v_strip.y) * (1.0 - on_verge);
  float strip_w = mix(max(v_strip.y - 100.0 * driving, 0.01), sign(v_strip.y), on_verge);
  // Across its strip from the right (0 .. 1); on a verge, the metres beyond the paved edge.
  float lane_pos = (lat - v_strip.x) / strip_w;
  float verge_d = max(lane_pos, 0.0) * on_verge;

  // Surface frame: normal from the mesh, tangent along the track from the uv derivatives.
  vec3 n_geo = normalize(v_normal);
  vec3 dp_dx = dFdx(v_world), dp_dy = dFdy(v_world);
  vec2 duv_dx = dFdx(v_uv), duv_dy = dFdy(v_uv);
  vec3 t_along = dp_dx * duv_dy.x - dp_dy * duv_dx.x;  // direction of growing s
  t_along = normalize(t_along - n_geo * dot(n_geo, t_along) + 1e-6);
  vec3 t_lat = cross(n_geo, t_along);

  // The pavement's asphalt, then a band of stone setts on the shoulder, then gravel and grass.
  float verge = smoothstep(0.0, 0.05, verge_d);
  float setts_band = verge * step(verge_d, kSettsWidth);
  // One fetch, from the setts' layer or the asphalt's: it switches halfway through the 5 cm where
  // the pavement's colour blends into the setts'.
  vec4 relief = texture(ground_relief_tex, vec3(vec2(lat, s) / kGroundTile, step(0.5, setts_band)));
  // Fade the relief with distance, where its texels get smaller than a pixel (the setts', four
  // times the size, later).
  float px = length(fwidth(v_uv));
  float detail = clamp(1.5 - px * mix(6.0, 1.5, setts_band), 0.0, 1.0);
  vec3 rn = relief.rgb * 2.0 - 1.0;
  vec3 n = normalize(mix(n_geo, normalize(t_lat * rn.x + t_along * rn.y + n_geo * rn.z), detail));

  // Asphalt: light aggregate in dark binder; worn, darker wheel paths; patches.
  float h = relief.a;
  float patches = value_noise_filtered(vec2(lat, s) / 5.0, px / 5.0);  // 5 m cells
  vec3 albedo = vec3(mix(0.055, 0.16, smoothstep(0.15, 0.8, h))) * (0.85 + 0.3 * patches);
  float wheel_paths = stripe(lane_pos, 0.27, 0.09) + stripe(lane_pos, 0.73, 0.09);
  albedo *= 1.0 - 0.18 * clamp(wheel_paths, 0.0, 1.0) * driving;

  // Markings: the lines on the two borders of this pixel's lane, as its profile has them (broken
  // lines 3 m on, 9 m off).
  // (No branch: the stripes' derivatives need every pixel to take the same path.)
  float pixel_w = max(fwidth(lat), 1e-4);
  float dash = step(fract(s / 12.0), 0.25);
  vec2 paint_yellow = lane_mark(v_strip.z, lane_pos * strip_w, pixel_w, dash) +
                      lane_mark(v_strip.w, (lane_pos - 1.0) * strip_w, pixel_w, dash);
  float paint = clamp(paint_yellow.x, 0.0, 1.0);
  vec3 paint_colour = mix(vec3(0.72, 0.72, 0.68), vec3(0.62, 0.47, 0.1),
                          clamp(paint_yellow.y / max(paint_yellow.x, 1e-3), 0.0, 1.0));
  albedo = mix(albedo, paint_colour, paint);
  n = normalize(mix(n, n_geo, paint * 0.8));  // paint fills the relief

  // Beyond the pavement: grey setts in sand (each stone its own shade), gravel, then grass.
  float course = floor(s / kSettsTile * 10.0);  // relief.hpp: 8 setts across a tile, 10 courses
  vec2 sett_id = vec2(floor(lat / kSettsTile * 8.0 + 0.5 * mod(course, 2.0)), course);
  float stone = fract(sin(dot(sett_id, vec2(12.9898, 78.233))) * 43758.5453);
  vec3 sett = vec3(0.2, 0.19, 0.18) * (0.75 + 0.5 * stone) * mix(0.55, 1.0, smoothstep(0.2, 0.5, relief.a));
  vec3 gravel = vec3(0.16, 0.15, 0.13) * (0.7 + 0.6 * h);
  vec3 grass = vec3(0.11, 0.16, 0.06) * (0.8 + 0.4 * patches);
  vec3 beyond = mix(gravel, grass, smoothstep(1.6, 2.8, verge_d));
  albedo = mix(albedo, mix(beyond, sett, setts_band), verge);

  // The water here (seed 003): the pores of the texture fill (wet: darker, the diffuse reduction
  // hd), a film stands over them (drench: smoother, a blurred mirror), then a puddle (a mirror
  // that ripples under the drops, over the ground seen through it).
  vec2 water = water_at(v_world.xy);
  float weather_wet = frame.wetness;
  // Off the pavement the verge drinks the rain: wet by the weather alone, never standing water.
  float fill = mix(clamp(water.x / frame.road_water_state.x, 0.0, 1.0), weather_wet, verge);
  float film = smoothstep(0.0, 0.3, water.y) * (1.0 - verge);
  float pool = smoothstep(0.6, 2.0, water.y) * (1.0 - verge);
  albedo *= mix(1.0, 0.5, fill) * mix(1.0, 0.7, film);
  vec3 view = normalize(frame.camera_pos.xyz - v_world);
  // The relief's shadows under the sun, not where paint or a film of water fills the relief.
  float on_setts = step(0.5, setts_band);
  float shadow_shows = (1.0 - paint * (1.0 - on_setts)) * (1.0 - film);
  float lit = mix(u_relief_mean_lit.x, u_relief_mean_lit.y, on_setts);
#ifdef ROAD_RELIEF
  vec3 l = vec3(dot(frame.sun_dir.xyz, t_lat), dot(frame.sun_dir.xyz, t_along),
                dot(frame.sun_dir.xyz, n_geo));
  vec2 relief_tex = vec2(lat, s) / mix(kReliefTile, kSettsTile, on_setts);
  float relief_h = relief.a * mix(u_relief_depth_m.x, u_relief_depth_m.y, on_setts);
  // Shadows texel by texel where a pixel covers a few texels (the asphalt's up to 1-3 cm, the
  // setts' 1.5-4 cm: within some metres of the camera); further off, their mean, not a pixel's
  // pick of them. This program draws only the road near the camera (road_pass.cpp), since
  // llvmpipe would run a branch around it on every pixel.
  float resolved = 1.0 - smoothstep(mix(0.01, 0.015, on_setts), mix(0.03, 0.04, on_setts), px);
  lit = mix(lit, relief_lit(l, relief_tex, on_setts * float(u_horizon_directions), relief_h),
            resolved);
  // At night, the ego car's beams: the relief's shadows seen from between its two headlamps (the
  // first two of the lamp block), taken from their light here per pixel, which the lamp map holds
  // unshadowed. (Further off, where the shadows are not resolved, the beams' light stays whole.)
#ifdef NO_LAMPS
  vec3 beams_shadowed = vec3(0.0);
#else
  vec3 beams = ego_headlights(v_world, n);
  vec3 to_beams = normalize(0.5 * (lamps.lamp[0].xyz + lamps.lamp[4].xyz) - v_world);
  vec3 lb = vec3(dot(to_beams, t_lat), dot(to_beams, t_along), dot(to_beams, n_geo));
  float beams_lit = relief_lit(lb, relief_tex, on_setts * float(u_horizon_directions), relief_h);
  vec3 beams_shadowed = beams * ((1.0 - beams_lit) * resolved * shadow_shows);
#endif
#else
  vec3 beams_shadowed = vec3(0.0);
#endif
  float sun_lit = mix(1.0, lit, shadow_shows);
  vec3 lamps_here = max(lamp_ground(v_world) * max(n.z, 0.0) - beams_shadowed, 0.0);
  vec3 colour = albedo * (diffuse_light_shadowed(n, sun_lit) + lamps_here);

  vec3 n_refl = normalize(mix(mix(n, n_geo, 0.8 * film), n_geo, pool));
#ifdef ROAD_RIPPLES
  n_refl = normalize(n_refl + ripple_slope(v_world.xy, water.y) * pool);
#endif
  float cos_v = dot(n_refl, view);
  vec3 r = reflect(-view, n_refl);
  float fresnel = fresnel_water(cos_v);
  // Gravel and grass off the pavement never mirror: a wet sheen at most. On the pavement the
  // mirror strengthens and sharpens as the water rises over the texture: streaked along the view
  // on a thin film (the texture's peaks still break it), clear once 1.2 mm stand over them (a
  // flooded road, a puddle).
  float smooth_water = film;
  float k = fresnel * mix(0.2 + 0.3 * fill * (1.0 - verge), 1.0, max(smooth_water, pool));
  vec3 refl = sky_gradient(r);
#ifdef ROAD_MIRROR
  float streak = 1.0 - smoothstep(0.3, 1.2, water.y);
  refl = mix(refl, mirrored(v_world, r, refl, streak), step(1e-3, smooth_water));
#ifndef NO_LAMPS
  refl += lamp_glints(v_world, n_refl, view) * max(smooth_water, pool);
#endif
#endif
  // A sheen of the sun on the film, broader than the sun in the mirror.
  float sun = max(dot(r, frame.sun_dir.xyz), 0.0);
  float s2 = sun * sun, s4 = s2 * s2, s8 = s4 * s4;
  refl += frame.sun_radiance.rgb * (s8 * s8) * 0.6 * film * (1.0 - frame.overcast * 0.7);
  // The mirror has its own haze (drawn from the mirrored eye along the whole path): only the ground
  // takes the haze of its own distance.
  out_colour = vec4(to_display(apply_fog(colour * (1.0 - k), v_fog) + refl * k), 1.0);
}
