#version 450
// A lamp's spot in an environment probe's face: a Gaussian a texel wide whose weights sum to one
// over the point, so that the spot's light is the lamp's at the probe.
in vec3 v_light;
out vec4 out_colour;
void main() {
  vec2 d = (gl_PointCoord - 0.5) * 5.0;  // texels from the spot's centre
  float weight = exp(-0.5 * dot(d, d)) / 6.2831853;
  out_colour = vec4(v_light * weight, 0.0);
}
