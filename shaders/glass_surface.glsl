// The surface of the water on the glass (sim::WaterBody, glass_water_surface.hpp): where a glass
// point lies under water, and the height, slope and bending of the body over it. Millimetres. (In
// texture buffers, not storage buffers: llvmpipe fetches texels for eight pixels at once, where it
// loads a storage buffer's words one pixel at a time.)
uniform ivec2 u_cells;     // the grid's cells across and up
uniform float u_cell_mm;   // a cell's side
uniform uint u_count_bits;  // a cell's listing: first entry << bits | count

struct WaterSurface {
  float height;   // mm over the glass; water where > 0
  vec2 slope;     // its gradient over the glass (u, v)
  float bending;  // the curvature of its profile, 1 / mm (1 / R on a cap)
};

// One body as its texture buffer holds it (three texels).
struct Body {
  vec4 place;  // centre (u, v), axis (unit)
  vec4 reach;  // across, ahead, behind, half its length
  vec4 angle;  // of the contact angle: 1 / sin^2, cot, tan; the flat top's thickness
};
Body body_at(uint k) {
  int at = 3 * int(k);
  return Body(texelFetch(glass_bodies_tex, at), texelFetch(glass_bodies_tex, at + 1),
              texelFetch(glass_bodies_tex, at + 2));
}

// A body's outline through p: rho (the fraction of the way out from its centre line to its
// outline, along the line through p) and its gradient over the glass.
struct Outline {
  float rho;
  vec2 drho;
};
Outline body_outline(vec4 place, vec4 reach, vec2 p) {
  vec2 d = p - place.xy, along = place.zw, across = vec2(-along.y, along.x);
  float x = dot(d, along), y = dot(d, across);
  x -= clamp(x, -reach.w, reach.w);  // a cylinder's own length is flat along it
  vec2 half_axes = vec2(x >= 0.0 ? reach.y : reach.z, reach.x);
  float rho = length(vec2(x, y) / half_axes);
  vec2 drho = (along * (x / (half_axes.x * half_axes.x)) +
               across * (y / (half_axes.y * half_axes.y))) / max(rho, 1e-5);
  return Outline(rho, drho);
}

// The square of a body's rho at p (body_outline's), for the search through a cell's bodies.
float body_rho2(vec4 place, vec4 reach, vec2 p) {
  vec2 d = p - place.xy;
  float x = dot(d, place.zw), y = d.y * place.z - d.x * place.w;
  x -= clamp(x, -reach.w, reach.w);
  vec2 q = vec2(x, y) / vec2(x >= 0.0 ? reach.y : reach.z, reach.x);
  return dot(q, q);
}

// One body's surface over p, a fraction rho of the way out from its centre line to its outline:
// the profile of a cap of radius r (its reach across: a round drop's radius) meeting the glass at
// the contact angle, r (sqrt(1 / sin^2 - rho^2) - cot), stretched to the outline (a longer body
// meets the glass less steeply at its ends); where flattened, a smooth minimum with a flat top t mm
// thick that the edge reaches over some capillary lengths, t (1 - exp(-x tan / t)) at x = r
// (1 - rho) mm in from the edge; beyond the outline, on down at the contact angle (so that a Newton
// step that overshoots the edge comes back).
WaterSurface body_surface(Body b, vec2 p) {
  vec4 angle = b.angle;
  Outline o = body_outline(b.place, b.reach, p);
  float rho = o.rho, r = b.reach.x;
  float inv_sin2 = angle.x, cot = angle.y, tn = angle.z, top = angle.w;
  // Height and its first two derivatives in rho.
  float h, dh, d2h;
  if (rho < 1.0) {
    float root = sqrt(inv_sin2 - rho * rho);
    h = r * (root - cot);
    dh = -r * rho / root;
    d2h = -r * inv_sin2 / (root * root * root);
    if (top > 0.0) {
      float e = exp(-(1.0 - rho) * r * tn / top);
      float hp = top * (1.0 - e), dhp = -r * tn * e, d2hp = -r * r * tn * tn * e / top;
      float k = 0.25 * top;
      float w = clamp(0.5 + 0.5 * (hp - h) / k, 0.0, 1.0);  // 1: the cap is lower
      h = mix(hp, h, w) - k * w * (1.0 - w);
      dh = mix(dhp, dh, w);
      d2h = mix(d2hp, d2h, w);
    }
  } else {
    h = -(rho - 1.0) * r * tn;
    dh = -r * tn;
    d2h = 0.0;
  }
  float g = 1.0 + (dh / r) * (dh / r);  // 1 + the profile's slope squared
  return WaterSurface(h, dh * o.drho, abs(d2h) / (r * r * g * sqrt(g)));
}

// The blurred layer's usual pair of samples of a pixel whose footprint on the glass has sides dx
// and dy: a diagonal pair, a quarter of the footprint either side of its centre.
void pair_samples(vec2 centre, vec2 dx, vec2 dy, out vec2 p0, out vec2 p1) {
  p0 = centre - 0.25 * (dx + dy);
  p1 = centre + 0.25 * (dx + dy);
}

// The listing of the grid cell under glass point p: first entry << u_count_bits | count (0 off the
// grid).
uint cell_listing(vec2 p) {
  ivec2 cell = ivec2(floor(p / u_cell_mm));
  if (any(lessThan(cell, ivec2(0))) || any(greaterThanEqual(cell, u_cells))) return 0u;
  return texelFetch(glass_cells_tex, cell.y * u_cells.x + cell.x).r;
}

// Whether glass point p lies under water, and the body that rises highest there, whose surface
// the light meets: of the bodies listed in p's cell, those whose outline holds p, by their cap's
// height there, about r (1 - rho^2) (a sub-metaball near a drop's centre stays under it).
bool water_top(vec2 p, out uint top) {
  top = 0u;
  uint listing = cell_listing(p);
  uint first = listing >> u_count_bits, count = listing & ((1u << u_count_bits) - 1u);
  float highest = 0.0;
  for (uint i = 0u; i < count; ++i) {
    uint k = texelFetch(glass_entries_tex, int(first + i)).r;
    vec4 reach = texelFetch(glass_bodies_tex, 3 * int(k) + 1);
    float height = reach.x * (1.0 - body_rho2(texelFetch(glass_bodies_tex, 3 * int(k)), reach, p));
    top = height > highest ? k : top;
    highest = max(highest, height);
  }
  return highest > 0.0;
}
