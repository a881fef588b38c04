#version 450
// Seed 001, step 3: the exact distances (along the view axis) where the pixel's ray enters and
// leaves the parcel's sphere (Kanamori's ray-cast squares), in all four maps at once: one RGBA32F
// target blended with MIN holds the body's front (r) and back (g, negated, so that MIN keeps the
// farthest), and the spray's (b, a). The mask (the depth, kept at its greatest) marks the pixel as
// the body's (0.5) or only the spray's (0.25). The scene's
// depth is applied where the maps are read (spray_shade.frag), as for the CPU's maps.
flat in vec4 v_centre;
flat in int v_body;
in vec3 v_ray;
out vec4 out_depth;
void main() {
  vec3 d = v_ray / -v_ray.z;  // the ray with unit step along the view axis
  vec3 c = v_centre.xyz;
  float dd = dot(d, d), dc = dot(d, c);
  float disc = dc * dc - dd * (dot(c, c) - v_centre.w * v_centre.w);
  if (disc <= 0.0) discard;
  float s = sqrt(disc);
  float front = (dc - s) / dd, back = (dc + s) / dd;
  if (front <= 0.0) discard;
  const float far = 1.0e6;
  gl_FragDepth = v_body == 1 ? 0.5 : 0.25;
  out_depth = v_body == 1 ? vec4(front, -back, far, far) : vec4(far, far, front, -back);
}
