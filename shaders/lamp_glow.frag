#version 450
// A lamp's glow: a core a pixel across in the lens's colour, and a halo falling off as a Gaussian
// to its radius; added to the view (display units, alpha 0: premultiplied blending adds it).
in vec2 v_offset_px;
flat in vec4 v_colour;
flat in float v_radius;
flat in float v_core;
out vec4 out_colour;
void main() {
  float r = length(v_offset_px);
  float core = (1.0 - smoothstep(0.5, 1.5, r)) * v_core;
  float q = r / v_radius;
  float halo = v_colour.a * exp(-3.0 * q * q);
  out_colour = vec4(v_colour.rgb * (core + halo), 0.0);
}
