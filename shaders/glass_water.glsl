// The water on the windshield as the view sees it (glass_water_pass.hpp), shared by its programs:
// glass_water.frag (sharp: the view's own image for rays that barely turn, three Newton steps),
// glass_water_blurred.frag (GLASS_BLURRED: the environment alone, one step) and
// glass_water_pair.frag (blurred, and GLASS_PAIR: two samples a pixel, known when compiled).
// llvmpipe pays for every instruction of a shader on every pixel, whatever its branches take, so
// what a program can do without is left out of it, not skipped at run time.
#include "common.glsl"
#include "glass_surface.glsl"
in vec2 v_glass_mm;
in vec3 v_world;
out vec4 out_colour;
uniform vec3 u_glass_u;  // unit axes, world
uniform vec3 u_glass_v;
uniform float u_water_ior;
uniform int u_samples;           // per layer pixel: 2 (a diagonal pair), 4 (2 x 2) or 16 (4 x 4)
uniform float u_env_per_rad;     // the environment's texels per radian at its finest level
uniform mat4 u_env_from_world;   // world directions into the environment's axes
uniform float u_env_max_lod;
uniform vec3 u_cabin;            // the cabin's radiance, seen down through the glass
uniform vec3 u_glass_depth;      // the glass plane's depth over the view: dot(xyz, (uv, 1))
uniform float u_view_pixel_rad;  // one pixel of the view, radians
uniform vec2 u_inv_target;       // one layer pixel in the view's uv

#ifdef GLASS_BLURRED
const int kNewtonSteps = 1;  // the tangent plane's hit: the lens's blur hides the rest
#else
const int kNewtonSteps = 3;
#endif

// Decoded display colour of the view's own image where a ray that the water barely turns lands,
// or the environment's; `spread` (radians) is the angle between neighbouring samples' rays.
// Blurred, the environment's alone: where the lens blurs, its texels are as sharp as needed.
vec3 outside(vec3 dir, float spread) {
  float lod = clamp(log2(max(spread * u_env_per_rad, 1e-6)), 0.0, u_env_max_lod);
  vec3 env = textureLod(environment_tex, mat3(u_env_from_world) * dir, lod).rgb;
#ifdef GLASS_BLURRED
  return env;
#else
  float px = spread / u_view_pixel_rad;
  if (px >= 4.0) return env;
  vec4 clip = frame.view_proj * vec4(dir, 0.0);
  if (clip.w <= 0.0) return env;
  vec2 uv = clip.xy / clip.w * 0.5 + 0.5;
  if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0)))) return env;
  // Reversed-Z: the cabin is nearer than the glass; it is not outside.
  if (textureLod(view_depth_tex, uv, 0.0).r > dot(u_glass_depth, vec3(uv, 1.0))) return env;
  vec3 seen = from_display(textureLod(view_colour_tex, uv, 0.0).rgb);
  return mix(seen, env, smoothstep(1.0, 4.0, px));
#endif
}

// The light that reaches the eye through body `top` at glass point p along w, the ray in the water
// (glass frame: u, v, out of the glass), of which dir_of turns glass-frame directions into the
// world's. spacing: mm between neighbouring samples.
vec3 through_water(vec2 p, uint top, vec3 w, float spacing, mat3 dir_of) {
  Body body = body_at(top);
  // Where the ray meets the surface of the body that rises highest over p: s along it, by
  // Newton's method on s w.z - height(p + s w.xy) from s = 0 (its first step the surface's
  // tangent plane over p).
  WaterSurface s = body_surface(body, p);
  float t = 0.0;
  for (int i = 0; i < kNewtonSteps; ++i) {
    float f = t * w.z - s.height, df = w.z - dot(s.slope, w.xy);
    t = max(t - f / max(df, 0.05), 0.0);
    s = body_surface(body, p + t * w.xy);
  }
  vec3 n = normalize(vec3(-s.slope, 1.0));
  // Cosine inside the water, leaving (a Newton step that ends on the far side of a steep edge may
  // see the surface from behind: taken as grazing).
  float ci = max(dot(w, n), 1e-3);
  float k = 1.0 - u_water_ior * u_water_ior * (1.0 - ci * ci);
  // Reflected inside: down through the glass into the cabin, unless too oblique to leave it.
  vec3 r = reflect(w, n);
  vec3 inside = u_water_ior * length(r.xy) < 1.0 && r.z < 0.0 ? u_cabin : vec3(0.0);
  if (k <= 0.0) return inside;  // total internal reflection
  float ct = sqrt(k);
  // Fresnel, unpolarised, from water into air.
  float rs = (u_water_ior * ci - ct) / (u_water_ior * ci + ct);
  float rp = (ci - u_water_ior * ct) / (ci + u_water_ior * ct);
  float fresnel = 0.5 * (rs * rs + rp * rp);
  vec3 leaving = u_water_ior * w + (ct - u_water_ior * ci) * n;
  // Neighbouring samples' normals differ by the surface's bending times their spacing; the ray
  // leaving turns by (n cos_in / cos_out - 1) times that.
  float gain = abs(u_water_ior * ci / max(ct, 0.05) - 1.0);
  float spread = s.bending * spacing * gain + u_view_pixel_rad * inversesqrt(float(u_samples));
  return mix(outside(normalize(dir_of * leaving), spread), inside, fresnel);
}

// The ray in the water: the eye's through this pixel, turned into the glass's frame (u, v, out of
// the car) and refracted into the water; dir_of turns that frame's directions into the world's.
struct WaterRay {
  vec3 w;
  mat3 dir_of;
};
WaterRay water_ray() {
  vec3 view = normalize(v_world - frame.camera_pos.xyz);
  vec3 normal = normalize(cross(u_glass_v, u_glass_u));  // out of the car
  vec3 eye = vec3(dot(view, u_glass_u), dot(view, u_glass_v), dot(view, normal));
  return WaterRay(refract(eye, vec3(0.0, 0.0, -1.0), 1.0 / u_water_ior),
                  mat3(u_glass_u, u_glass_v, normal));
}

// The layer's pixel from the light of its `wet` samples of n that met water (their sum):
// premultiplied over the view, which the composite adds as it is displayed. What the pixel shows
// is the display of the light's mean, water and the glass beside it mixed as light.
vec4 layer_pixel(vec3 sum, int wet, float n) {
  vec3 behind = textureLod(view_colour_tex, gl_FragCoord.xy * u_inv_target, 0.0).rgb;
  vec3 shown = to_display((sum + (n - float(wet)) * from_display(behind)) / n);
  float coverage = float(wet) / n;
  return vec4(max(shown - (1.0 - coverage) * behind, 0.0), coverage);
}

// llvmpipe runs both sides of a branch on every pixel; loops and a discard are its real branches.
// So: first where the samples meet water (cheap), a discard where none does, then the optics in a
// loop over the wet samples alone.
#ifdef GLASS_PAIR
// A diagonal pair of samples: the pair in variables, not arrays (which llvmpipe keeps in memory,
// a lane at a time, where an index is not known when compiled).
void main() {
  vec2 dx = dFdx(v_glass_mm), dy = dFdy(v_glass_mm);  // the pixel's footprint on the glass, mm
  vec2 p0, p1;
  pair_samples(v_glass_mm, dx, dy, p0, p1);
  uint b0, b1;
  bool w0 = water_top(p0, b0), w1 = water_top(p1, b1);
  if (!(w0 || w1)) discard;
  WaterRay ray = water_ray();
  float spacing = max(length(dx), length(dy)) * inversesqrt(2.0);
  int wet = int(w0) + int(w1);
  vec3 sum = through_water(w0 ? p0 : p1, w0 ? b0 : b1, ray.w, spacing, ray.dir_of);
  for (int k = 1; k < wet; ++k) sum += through_water(p1, b1, ray.w, spacing, ray.dir_of);
  out_colour = layer_pixel(sum, wet, 2.0);
}
#else
const int kMaxSamples = 16;

// Sample k's place in the pixel, from its centre, in pixels.
vec2 sample_offset(int k) {
  if (u_samples == 2) return vec2(k == 0 ? -0.25 : 0.25);
  int side = u_samples == 16 ? 4 : 2;
  return (vec2(k % side, k / side) + 0.5) / float(side) - 0.5;
}

void main() {
  vec2 dx = dFdx(v_glass_mm), dy = dFdy(v_glass_mm);  // the pixel's footprint on the glass, mm
  vec2 at[kMaxSamples];
  uint top[kMaxSamples];
  int wet = 0;
  for (int k = 0; k < u_samples; ++k) {
    vec2 o = sample_offset(k);
    vec2 p = v_glass_mm + o.x * dx + o.y * dy;
    uint body;
    if (water_top(p, body)) {
      at[wet] = p;
      top[wet] = body;
      ++wet;
    }
  }
  if (wet == 0) discard;
  WaterRay ray = water_ray();
  float n = float(u_samples);
  float spacing = max(length(dx), length(dy)) * inversesqrt(n);
  vec3 sum = vec3(0.0);
  for (int k = 0; k < wet; ++k) sum += through_water(at[k], top[k], ray.w, spacing, ray.dir_of);
  out_colour = layer_pixel(sum, wet, n);
}
#endif
