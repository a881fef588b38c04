// The wiper blades in glass space, shared by the glass shaders (wiper_blades.cpp sets them).
uniform vec4 u_blade_pivot_dir[WIPER_BLADES];  // xy pivot (mm), zw unit direction to the tip
uniform vec2 u_blade_size[WIPER_BLADES];  // x length from the pivot (mm), y width of the rubber (mm)

// Coverage in [0, 1] of the blades (x: rubber strips) and of their arms and pivots (y) at glass
// point p (mm); edges soften over aa mm. The rubber runs over the outer 85 % of the wiped length;
// the arm from the pivot to the blade's middle, along its upper side.
vec2 wiper_coverage(vec2 p, float aa) {
  vec2 cover = vec2(0.0);
  for (int i = 0; i < 2; ++i) {
    float len = u_blade_size[i].x;
    float w = u_blade_size[i].y;
    if (len <= 0.0 || w <= 0.0) continue;
    vec2 d = p - u_blade_pivot_dir[i].xy;
    vec2 dir = u_blade_pivot_dir[i].zw;
    float along = dot(d, dir);
    float across = dot(d, vec2(-dir.y, dir.x));
    float rubber = max(max(0.15 * len - along, along - len), abs(across) - 0.5 * w);
    float arm = max(max(-along, along - 0.6 * len), abs(across - 0.55 * w) - 0.35 * w);
    float hub = length(d) - 0.9 * w;
    cover.x = max(cover.x, clamp(0.5 - rubber / aa, 0.0, 1.0));
    cover.y = max(cover.y, clamp(0.5 - min(arm, hub) / aa, 0.0, 1.0));
  }
  return cover;
}
