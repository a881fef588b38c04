#version 450
// The glass in its own plane, fitted to the view: dry glass is black (no water); its outline is
// drawn faintly so that the image shows where the glass is.
in vec2 v_uv;
out vec4 out_colour;
uniform vec3 u_glass;  // bottom width, top width, height (m)
uniform float u_aspect;
void main() {
  float margin = 1.1;
  float scale = max(u_glass.x / u_aspect, u_glass.z) * margin;  // metres across the view's height
  vec2 p = (v_uv - 0.5) * vec2(u_aspect, 1.0) * scale;           // metres, origin at the glass centre
  float v = p.y / u_glass.z + 0.5;                                // 0 bottom .. 1 top edge
  float half_width = 0.5 * mix(u_glass.x, u_glass.y, clamp(v, 0.0, 1.0));
  float inside = step(abs(p.x), half_width) * step(0.0, v) * step(v, 1.0);
  float edge_dist = min(half_width - abs(p.x), min(v, 1.0 - v) * u_glass.z);
  float px = fwidth(p.x);
  float outline = inside * (1.0 - smoothstep(px, 2.0 * px, edge_dist));
  out_colour = vec4(vec3(0.25 * outline), 1.0);
}
