#version 450
// Seed 001, step 4 (the baseline): the bilateral filter of the body's front depth (the paper's
// eq. 3.1), spatial sigma u_sigma_px, range sigma u_sigma_z.
#include "spray_common.glsl"
// The kernel's half width, a constant: llvmpipe unrolls a loop of constant bounds, and pays for
// a loop of uniform ones on every turn.
const int kRadius = 3;  // a 7x7 kernel
uniform float u_sigma_px;
uniform float u_sigma_z;
out float out_z;
void main() {
  ivec2 px = ivec2(gl_FragCoord.xy);
  float z0 = texelFetch(spray_smooth_tex, px, 0).r;
  float a = 0.5 / (u_sigma_px * u_sigma_px), b = 0.5 / (u_sigma_z * u_sigma_z);
  // (A nearest, clamped sampler: on llvmpipe a third cheaper than texelFetch with a clamp.)
  vec2 texel = 1.0 / u_size;
  vec2 uv0 = (vec2(px) + 0.5) * texel;
  float sw = 0.0, sz = 0.0;
  for (int j = -kRadius; j <= kRadius; ++j) {
    for (int i = -kRadius; i <= kRadius; ++i) {
      float z = textureLod(spray_smooth_tex, uv0 + vec2(i, j) * texel, 0.0).r;
      float dz = z - z0;
      float w = exp(-float(i * i + j * j) * a - min(dz * dz * b, 60.0));
      sw += w;
      sz += w * z;
    }
  }
  out_z = z0 < kFar * 0.5 ? sz / sw : z0;
}
