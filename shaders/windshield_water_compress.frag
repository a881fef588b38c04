#version 450
// Height compression, threshold and normals in one pass (seed 000, section 1.5 steps 2-4): each
// texel and its four neighbours in the raw height map are compressed, the normal comes from the
// central differences of the compressed heights. Beyond the paper, lenses: a lone drop is a
// spherical cap, whose surface leans sin(contact angle) * h / R at distance h from the centre of a
// drop of contact radius R; h / R comes back from the raw density, N = 1 / (1 + (h/R)^4). Where the
// compressed heights lean more (drops run together), they win. Without this the compressed
// plateaus are flat: drops would show only an edge and no image of the world turned over.
// Out: (normal u, normal v) * 0.5 + 0.5, compressed height, water coverage (the threshold,
// anti-aliased over a texel).
layout(binding = 4) uniform sampler2D height_tex;
uniform float u_k;
uniform float u_first_level;
uniform float u_level_step;
uniform int u_steps;
uniform float u_threshold;
uniform float u_height_scale_mm;  // water mm per unit of compressed height
uniform float u_texels_per_mm;
uniform float u_contact_sin;  // sine of the contact angle
out vec4 out_water;

float compress(float v) {
  float level = u_first_level;
  for (int i = 0; i < u_steps; ++i) {
    v = v > level ? u_k * (v - level) + level : v;
    level += u_level_step;
  }
  return v;
}

void main() {
  // Two gathers: the 2 x 2 texels below-left of this one's centre and above-right of it.
  vec2 texel = 1.0 / vec2(textureSize(height_tex, 0));
  vec4 below_left = textureGather(height_tex, (gl_FragCoord.xy - 0.5) * texel);
  vec4 above_right = textureGather(height_tex, (gl_FragCoord.xy + 0.5) * texel);
  float raw = below_left.y;
  float c = compress(raw);
  float l = compress(below_left.x);
  float d = compress(below_left.z);
  float r = compress(above_right.z);
  float u = compress(above_right.x);
  vec2 slope = 0.5 * vec2(r - l, u - d);  // height per texel
  vec2 gradient = slope * u_texels_per_mm;  // per glass mm
  vec3 n = normalize(vec3(-gradient * u_height_scale_mm, 1.0));
  float steepness = length(gradient);
  float off_centre = sqrt(sqrt(max(1.0 / max(raw, 1e-6) - 1.0, 0.0)));  // h / R
  float lean = u_contact_sin * min(off_centre, 1.0);
  vec2 tilt = length(n.xy) < lean && steepness > 1e-6 ? -gradient / steepness * lean : n.xy;
  // The threshold's edge placed within the texel from the local slope.
  float mask = clamp((c - u_threshold) / max(max(abs(slope.x), abs(slope.y)), 1e-4) + 0.5, 0.0, 1.0);
  out_water = vec4(tilt * 0.5 + 0.5, clamp(c, 0.0, 1.0), mask);
}
