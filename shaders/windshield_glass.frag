#version 450
// The water on the windshield over the scene (seed 000, section 1.5 step 5), premultiplied alpha.
// Water refracts: the scene behind, blurred (a mip of a small copy), looked up at an offset against
// the normal's glass-parallel part (drops are lenses: the image turns over), with a Fresnel
// reflection of the sky and rims darkened where the surface is steep. Dry glass is left alone.
#include "common.glsl"
in vec2 v_glass_mm;
in vec3 v_world;
out vec4 out_colour;
layout(binding = 5) uniform sampler2D water_tex;  // WindshieldWaterPass's water map
layout(binding = 6) uniform sampler2D scene_tex;  // the scene, small, mipmapped, mirrored repeat
uniform vec3 u_glass_u;  // unit axes, world
uniform vec3 u_glass_v;
uniform vec3 u_glass_n;
uniform vec2 u_map_origin_mm;  // the water map covers u_map_extent_mm from here
uniform vec2 u_map_extent_mm;
uniform float u_water_lod;  // defocus of a close camera
uniform vec2 u_inv_viewport;
uniform vec4 u_screen_axes;  // screen directions of glass +u (xy) and +v (zw)
uniform vec2 u_refraction;   // uv offset per unit of the deflection angle's tangent
uniform float u_water_ior;
uniform float u_background_lod;
uniform float u_fresnel_r0;
uniform float u_rim_darkening;
uniform vec2 u_rim_lean;  // the lean where rims start to darken and where they are darkest

void main() {
  vec4 water = textureLod(water_tex, (v_glass_mm - u_map_origin_mm) / u_map_extent_mm, u_water_lod);
  float wet = water.a;
  if (wet < 0.004) discard;
  vec2 n = water.xy * 2.0 - 1.0;  // glass-parallel part of the surface normal
  float steep = dot(n, n);
  float lean = sqrt(steep);  // sine of the surface's tilt
  float bend = asin(min(u_water_ior * lean, 1.0)) - asin(min(lean, 1.0));
  vec2 towards = lean > 1e-4 ? n / lean : vec2(0.0);
  vec2 offset = -(towards.x * u_screen_axes.xy + towards.y * u_screen_axes.zw) * tan(bend) *
                u_refraction;
  vec3 behind =
      textureLod(scene_tex, gl_FragCoord.xy * u_inv_viewport + offset, u_background_lod).rgb;
  behind *= 1.0 - u_rim_darkening * smoothstep(u_rim_lean.x, u_rim_lean.y, lean);
  vec3 tilt = n.x * u_glass_u + n.y * u_glass_v;
  vec3 normal = tilt + sqrt(max(1.0 - steep, 0.0)) * u_glass_n;
  vec3 view = normalize(v_world - frame.camera_pos.xyz);
  float fresnel = schlick(abs(dot(view, normal)), u_fresnel_r0);
  // The sky that the tilted surface bends the ray towards, with the lookup.
  vec3 sky = to_display(sky_gradient(normalize(view - 2.0 * tilt)));
  out_colour = vec4(mix(behind, sky, fresnel) * wet, wet);
}
