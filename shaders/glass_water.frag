#version 450
// The water on the windshield as the view sees it (seed 000, section 1.5 step 5), drawn into the
// glass layer (premultiplied, at a reduced size that the lens's blur allows): each drop a lens.
// Looking out through the water, the ray leaves the curved water surface bent by
// asin(n sin a) - a away from the surface's tilt a: a drop shows the world behind it turned over,
// sky in its lower part and road in its upper part over the horizon. The refracted ray looks up
// the scene behind (a blurred copy) where it stays in the image, else the sky. Seen from inside,
// the surface reflects the dark cabin (Fresnel, from the water side); where it leans most the rays
// graze it and the rims darken; the sun, where a drop bends it into the eye, glints. At night the
// drops around a bright lamp bend its light into the eye: each holds a bright point of it.
#include "common.glsl"
in vec2 v_glass_mm;
in vec3 v_world;
out vec4 out_colour;
uniform vec2 u_map_size_mm;  // the glass water map covers [0, size] of glass space
uniform int u_taps;             // 1 (a sharp lens) or 4 (2 x 2 over a layer pixel)
uniform vec2 u_inv_target;      // one layer pixel in the view's uv
uniform vec4 u_screen_axes;     // screen directions of glass +u (xy) and +v (zw)
uniform vec2 u_refraction;      // uv offset per unit of the deflection angle's tangent
uniform vec3 u_glass_u;         // unit axes, world
uniform vec3 u_glass_v;
uniform float u_water_ior;
uniform float u_fresnel_r0;
uniform float u_rim_darkening;
uniform vec2 u_rim_lean;  // the lean where rims start to darken and where they are darkest
uniform float u_glint;    // the sun seen through a drop, relative to its direct light
uniform int u_lamp_count;
uniform vec4 u_lamps[8];  // per lamp: the unit direction towards it and the radiance its drops
                           // show (display units); its colour
uniform vec2 u_lamp_spread;  // cosines: full out to x from the lamp, none past y

// The light of the lamps that the water bends into the eye along `view` (per unit of coverage).
vec3 lamps_through_drops(vec3 view) {
  vec3 light = vec3(0.0);
  for (int i = 0; i < u_lamp_count; ++i) {
    float c = dot(view, u_lamps[2 * i].xyz);
    light += u_lamps[2 * i + 1].rgb * (u_lamps[2 * i].w * smoothstep(u_lamp_spread.y, u_lamp_spread.x, c));
  }
  return light;
}

// The light reaching the eye through the water at a glass point (premultiplied by its coverage);
// `curved` gains the coverage of curved water there (a drop's, not a flat film's: only a leaning
// surface bends the lamps around into the eye).
vec4 through_water(vec2 glass_mm, vec2 view_uv, vec3 view, inout float curved) {
  vec4 water = textureLod(glass_water_tex, glass_mm / u_map_size_mm, 0.0);
  float wet = water.a;
  if (wet < 0.002) return vec4(0.0);  // dry glass here
  vec2 n = water.xy * 2.0 - 1.0;  // glass-parallel part of the surface normal
  float lean = min(length(n), 1.0);  // sine of the surface's tilt
  curved += wet * smoothstep(0.05, 0.3, lean);
  float bend = asin(min(u_water_ior * lean, 1.0)) - asin(lean);
  vec2 towards = lean > 1e-4 ? n / lean : vec2(0.0);
  float deflect = tan(bend);
  vec2 uv = view_uv -
            (towards.x * u_screen_axes.xy + towards.y * u_screen_axes.zw) * deflect * u_refraction;
  // The refracted ray in the world: the view ray turned away from the tilt.
  vec3 ray = normalize(view - (towards.x * u_glass_u + towards.y * u_glass_v) * deflect);
  vec3 behind = all(equal(clamp(uv, 0.0, 1.0), uv))
                    ? textureLod(scene_blur_tex, uv, 0.0).rgb
                    : to_display(sky_gradient(ray));
  // The sun through the lens: a sharp image of its disc where the drop bends it into the eye.
  float s = max(dot(ray, frame.sun_dir.xyz), 0.0);
  s *= s; s *= s; s *= s; s *= s; s *= s; s *= s; s *= s; s *= s; s *= s; s *= s;  // s^1024
  behind += u_glint * s * (1.0 - frame.params.y) * frame.sun_radiance.rgb;
  behind *= 1.0 - u_rim_darkening * smoothstep(u_rim_lean.x, u_rim_lean.y, lean);
  // The cabin reflected from the water side of the surface (dark plastic, lit by the sky).
  float fresnel = schlick(sqrt(max(1.0 - lean * lean, 0.0)), u_fresnel_r0);
  vec3 cabin = to_display(frame.ambient.rgb * 0.03);
  return vec4(mix(behind, cabin, fresnel) * wet, wet);
}

void main() {
  vec3 view = normalize(v_world - frame.camera_pos.xyz);
  vec2 view_uv = gl_FragCoord.xy * u_inv_target;
  float curved = 0.0;
  if (u_taps == 1) {
    out_colour = through_water(v_glass_mm, view_uv, view, curved);
    if (out_colour.a < 0.002) discard;
    if (u_lamp_count > 0) out_colour.rgb += lamps_through_drops(view) * curved;
    return;
  }
  // The lens blurs what the eye sees through the water, not the water's shape: the optics at
  // 2 x 2 points of the pixel, averaged (the layer's magnification then blurs further).
  vec2 dx = 0.25 * dFdx(v_glass_mm), dy = 0.25 * dFdy(v_glass_mm);
  vec2 ux = 0.25 * u_inv_target * vec2(1.0, 0.0), uy = 0.25 * u_inv_target * vec2(0.0, 1.0);
  vec4 sum = through_water(v_glass_mm - dx - dy, view_uv - ux - uy, view, curved) +
             through_water(v_glass_mm + dx - dy, view_uv + ux - uy, view, curved) +
             through_water(v_glass_mm - dx + dy, view_uv - ux + uy, view, curved) +
             through_water(v_glass_mm + dx + dy, view_uv + ux + uy, view, curved);
  if (sum.a < 0.008) discard;
  out_colour = 0.25 * sum;
  if (u_lamp_count > 0) out_colour.rgb += lamps_through_drops(view) * (0.25 * curved);
}
