#version 450
// Height compression, threshold and normals in one pass (seed 000, section 1.5 steps 2-4): each
// texel and its four neighbours in the raw height map are compressed, the normal comes from the
// central differences of the compressed heights. Beyond the paper, a meniscus: within
// u_meniscus_mm of the water's edge the surface leans at least at the contact angle, whatever the
// drop's size (the metaballs' slope falls as 1/R: large drops would have no visible edge).
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
uniform float u_meniscus_mm;
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
  float c = compress(below_left.y);
  float l = compress(below_left.x);
  float d = compress(below_left.z);
  float r = compress(above_right.z);
  float u = compress(above_right.x);
  vec2 slope = 0.5 * vec2(r - l, u - d);  // height per texel
  vec2 gradient = slope * u_texels_per_mm;  // per glass mm
  vec3 n = normalize(vec3(-gradient * u_height_scale_mm, 1.0));
  // Distance to the edge from the local slope; the meniscus's lean fades over u_meniscus_mm.
  float steepness = length(gradient);
  float edge_mm = (c - u_threshold) / max(steepness, 1e-6);
  float lean = u_contact_sin * (1.0 - smoothstep(0.0, u_meniscus_mm, edge_mm));
  vec2 tilt = length(n.xy) < lean && steepness > 1e-6 ? -gradient / steepness * lean : n.xy;
  // The threshold's edge placed within the texel from the local slope.
  float mask = clamp((c - u_threshold) / max(max(abs(slope.x), abs(slope.y)), 1e-4) + 0.5, 0.0, 1.0);
  out_water = vec4(tilt * 0.5 + 0.5, clamp(c, 0.0, 1.0), mask);
}
