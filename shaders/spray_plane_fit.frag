#version 450
// Seed 001, step 4 (the paper's method): local plane fitting of the body's front depth. The
// pixel's and its neighbours' view-space points, weighted by exp(-(z0 - z)^2 / sigma^2), give a
// weighted covariance; the plane's normal is its eigenvector of the smallest eigenvalue (power
// iteration on trace - C, from the view axis), through the weighted centroid; the new depth is
// where the pixel's ray meets the plane, unless that moves it more than u_max_shift (a plane
// along the ray).
#include "spray_common.glsl"
// The kernel's half width, a constant: llvmpipe unrolls a loop of constant bounds, and pays for
// a loop of uniform ones on every turn.
const int kRadius = 4;  // a 9x9 kernel
uniform float u_sigma;
uniform float u_max_shift;
out float out_z;
void main() {
  ivec2 px = ivec2(gl_FragCoord.xy);
  float z0 = texelFetch(spray_smooth_tex, px, 0).r;
  // A neighbour at offset o with distance z, from the pixel's point: (n0 dz + k o z, -dz), with
  // n0 the pixel's ray slope and k the slope per pixel.
  vec2 k = 2.0 * u_tan / u_size;
  vec2 n0 = (vec2(px) + 0.5) * k - u_tan;
  float sw = 0.0;
  vec3 sp = vec3(0.0), sd = vec3(0.0), so = vec3(0.0);  // sums of w q, w q q (diagonal, off)
  float inv_s2 = 1.0 / (u_sigma * u_sigma);
  // (A nearest, clamped sampler: on llvmpipe a third cheaper than texelFetch with a clamp.)
  vec2 texel = 1.0 / u_size;
  vec2 uv0 = (vec2(px) + 0.5) * texel;
  for (int j = -kRadius; j <= kRadius; ++j) {
    for (int i = -kRadius; i <= kRadius; ++i) {
      float z = textureLod(spray_smooth_tex, uv0 + vec2(i, j) * texel, 0.0).r;
      float dz = z - z0;
      // (An empty neighbour's weight is e^-60: nothing, and its q stays finite.)
      float w = exp(-min(dz * dz * inv_s2, 60.0));
      vec3 q = vec3(n0 * dz + k * vec2(i, j) * z, -dz);
      vec3 wq = w * q;
      sw += w;
      sp += wq;
      sd += wq * q;
      so += wq.xxy * q.yzz;
    }
  }
  vec3 m = sp / sw;
  vec3 dg = sd / sw - m * m;
  vec3 of = so / sw - m.xxy * m.yzz;
  mat3 c = mat3(dg.x, of.x, of.y, of.x, dg.y, of.z, of.y, of.z, dg.z);
  float tr = dg.x + dg.y + dg.z + 1e-9;
  mat3 shifted = mat3(tr) - c;
  vec3 n = vec3(0.0, 0.0, 1.0);
  for (int it = 0; it < 8; ++it) n = normalize(shifted * n + 1e-12);
  // The plane through p0 + m with normal n; the pixel's ray is t (n0, -1), and p0 = z0 (n0, -1).
  vec3 dir = vec3(n0, -1.0);
  float along = dot(n, dir);
  float z = abs(along) > 1e-4 ? z0 + dot(n, m) / along : z0;
  out_z = (z0 < kFar * 0.5 && abs(z - z0) < u_max_shift) ? z : z0;
}
