#version 450
// Seed 001, steps 5-8: the liquid's colour at a spray pixel. Normals come from the depth maps
// (the body's front smoothed), each from the neighbour on the side with the smaller step. The
// pixel's ray meets the nearer front (body or spray), reflects the sky and refracts in; the
// secant method finds where it leaves through the same object's back (halving the step where the
// back map is empty there); it refracts out (or reflects, past the critical angle), and then
// meets the other object's front if that lies beyond: at most four surfaces, body then spray or
// spray then body. Each surface adds its Schlick reflection of the sky; what is left sees the scene
// behind along the last ray, absorbed by Beer-Lambert over the path in the liquid. The scene hides
// a front behind it and ends a back at it. Premultiplied: a drop smaller than the pixel covers
// its share of it.
#include "spray_common.glsl"
in vec2 v_uv;
uniform mat4 u_view_to_world;  // rotation only
uniform float u_near;
uniform int u_scale;
uniform vec3 u_absorption;  // per metre, rgb
out vec4 out_colour;

const float kIor = 1.33;
const float kR0 = 0.02;  // ((1.33 - 1) / (1.33 + 1))^2

float front_z(int object, ivec2 px) {
  px = clamp(px, ivec2(0), ivec2(u_size) - 1);
  return object == 0 ? texelFetch(spray_smooth_tex, px, 0).r : texelFetch(spray_depth_tex, px, 0).b;
}
float back_z(int object, ivec2 px) {
  px = clamp(px, ivec2(0), ivec2(u_size) - 1);
  vec4 d = texelFetch(spray_depth_tex, px, 0);
  return -(object == 0 ? d.g : d.a);
}
bool valid(float z) { return z > 0.0 && z < kFar * 0.5; }

// The surface's normal at px from a depth function, towards the camera for a front and away from
// it for a back.
#define NORMAL_FROM(fetch, object, px, z0, towards)                                         \
  {                                                                                          \
    vec3 p0 = view_point(vec2(px) + 0.5, z0);                                                \
    float zr = fetch(object, px + ivec2(1, 0)), zl = fetch(object, px - ivec2(1, 0));        \
    float zu = fetch(object, px + ivec2(0, 1)), zd = fetch(object, px - ivec2(0, 1));        \
    bool right = valid(zr) && (!valid(zl) || abs(zr - z0) < abs(zl - z0));                   \
    bool up = valid(zu) && (!valid(zd) || abs(zu - z0) < abs(zd - z0));                     \
    vec3 dx = right ? view_point(vec2(px + ivec2(1, 0)) + 0.5, zr) - p0                      \
                    : p0 - view_point(vec2(px - ivec2(1, 0)) + 0.5, valid(zl) ? zl : z0);    \
    vec3 dy = up ? view_point(vec2(px + ivec2(0, 1)) + 0.5, zu) - p0                         \
                 : p0 - view_point(vec2(px - ivec2(0, 1)) + 0.5, valid(zd) ? zd : z0);       \
    vec3 n = cross(dx, dy);                                                                  \
    n = dot(n, n) > 1e-20 ? normalize(n) : vec3(0.0, 0.0, 1.0);                              \
    normal = (n.z > 0.0) == towards ? n : -n;                                                \
  }

vec3 front_normal(int object, ivec2 px, float z0) {
  vec3 normal;
  NORMAL_FROM(front_z, object, px, z0, true)
  return normal;
}
vec3 back_normal(int object, ivec2 px, float z0) {
  vec3 normal;
  NORMAL_FROM(back_z, object, px, z0, false)
  return normal;
}

vec3 sky(vec3 dir_view) { return sky_gradient(normalize(mat3(u_view_to_world) * dir_view)); }
float scene_z(vec2 px) {
  ivec2 full = ivec2(clamp(px, vec2(0.0), u_size - 1.0)) * u_scale;
  return u_near / max(texelFetch(view_depth_tex, full, 0).r, 1e-12);
}
// The scene seen along a ray leaving the liquid at p: where it reaches the scene's depth there.
vec3 behind(vec3 p, vec3 dir) {
  float gap = max(scene_z(pixel_of(p)) + p.z, 0.02);
  vec3 q = p + dir * (gap / max(-dir.z, 0.25));
  vec2 uv = clamp(pixel_of(q) / u_size, vec2(0.0), vec2(1.0));
  return from_display(textureLod(view_colour_tex, uv, 0.0).rgb);
}
// From p inside `object` along dir, where the ray leaves through its back (the secant method on
// back(project(p + s dir)) - depth(p + s dir)); false if the back is nowhere near.
bool leave(int object, vec3 p, vec3 dir, out vec3 q) {
  float s0 = 0.0;
  float b0 = back_z(object, ivec2(pixel_of(p)));
  if (!valid(b0)) return false;
  float f0 = min(b0, scene_z(pixel_of(p))) + p.z;
  float s1 = max(f0 / max(-dir.z, 0.2), 0.002);
  for (int k = 0; k < 4; ++k) {
    q = p + dir * s1;
    float b = back_z(object, ivec2(pixel_of(q)));
    b = min(b, scene_z(pixel_of(q)));
    if (!valid(b)) {
      s1 *= 0.5;
      continue;
    }
    float f1 = b + q.z;
    if (abs(f1) < 1e-4 || abs(f1 - f0) < 1e-7) break;
    float s2 = s1 - f1 * (s1 - s0) / (f1 - f0);
    s0 = s1;
    f0 = f1;
    s1 = clamp(s2, 0.0, 4.0 * s1 + 0.05);
  }
  q = p + dir * s1;
  return true;
}

void main() {
  ivec2 px = ivec2(gl_FragCoord.xy);
  float body = front_z(0, px), spray = front_z(1, px);
  float scene = scene_z(vec2(px) + 0.5);
  bool has_body = valid(body) && body < scene, has_spray = valid(spray) && spray < scene;
  if (!has_body && !has_spray) {
    out_colour = vec4(0.0);
    return;
  }
  int first = has_body && (!has_spray || body <= spray) ? 0 : 1;
  vec3 dir = normalize(view_point(vec2(px) + 0.5, 1.0));
  vec3 colour = vec3(0.0);
  float through = 1.0, path = 0.0;
  vec3 p = dir * ((first == 0 ? body : spray) / -dir.z);
  int object = first;
  // The lamps' light that the water scatters towards the eye where it enters (a beam lights the
  // spray in it; the droplets' many faces scatter it every way, as the rain's drops do).
  vec3 to_world = mat3(u_view_to_world) * p;
  colour += 0.5 * lamps_scattered(frame.camera_pos.xyz + to_world, -normalize(to_world));
  for (int k = 0; k < 2; ++k) {
    // In at the front.
    vec3 n = front_normal(object, ivec2(pixel_of(p)), -p.z);
    float f = schlick(dot(-dir, n), kR0);
    colour += through * f * sky(reflect(dir, n));
    through *= 1.0 - f;
    dir = refract(dir, n, 1.0 / kIor);
    // Out at the back.
    vec3 q;
    if (!leave(object, p, dir, q)) break;
    path += distance(p, q);
    vec3 nb = back_normal(object, ivec2(pixel_of(q)), -q.z);
    vec3 out_dir = refract(dir, -nb, kIor);
    float fb = schlick(dot(dir, nb), kR0);
    if (dot(out_dir, out_dir) < 0.5) {  // past the critical angle
      fb = 1.0;
      out_dir = reflect(dir, -nb);
    }
    colour += through * fb * sky(reflect(dir, -nb)) * 0.5;
    through *= 1.0 - fb;
    dir = out_dir;
    p = q;
    // The other object, if its front lies beyond on this ray.
    object = 1 - object;
    if (k == 1) break;
    float other = front_z(object, ivec2(pixel_of(p)));
    if (!valid(other) || other <= -p.z || other >= scene_z(pixel_of(p))) break;
    p += dir * ((other + p.z) / max(-dir.z, 0.25));
  }
  colour += through * behind(p, dir) * exp(-u_absorption * path);
  // A body covers its pixels; a lone drop smaller than a pixel covers its share of it (its
  // radius from its thickness at the pixel's centre, about its largest).
  float coverage = 1.0;
  if (first == 1) {
    float radius_px = 0.5 * (back_z(1, px) - spray) * u_size.y / (2.0 * u_tan.y * spray);
    coverage = clamp(3.14159 * radius_px * radius_px, 0.05, 1.0);
  }
  out_colour = vec4(to_display(colour) * coverage, coverage);
}
