#include "server/sim/glass_water_surface.hpp"

#include <algorithm>
#include <cmath>

#include "server/sim/drop_physics.hpp"

namespace downpour::sim {
namespace {

// A steeper contact angle than this is drawn at it (tan stays finite).
constexpr double kSteepestDeg = 87.0;

void set_contact_angle(WaterBody& b, double contact_angle_deg) {
  const double q = std::clamp(contact_angle_deg, 1.0, kSteepestDeg) * M_PI / 180.0;
  const double s = std::sin(q), c = std::cos(q);
  b.inv_sin2 = static_cast<float>(1.0 / (s * s));
  b.cot = static_cast<float>(c / s);
  b.tan = static_cast<float>(s / c);
}

}  // namespace

double puddle_thickness_mm(double contact_angle_deg, double capillary_length_mm) {
  return 2.0 * capillary_length_mm * std::sin(0.5 * contact_angle_deg * M_PI / 180.0);
}

WaterBody cap_body(glm::vec2 centre, float radius, double contact_angle_deg, bool flatten,
                   double capillary_length_mm) {
  WaterBody b;
  b.u_mm = centre.x;
  b.v_mm = centre.y;
  b.side_mm = b.front_mm = b.back_mm = radius;
  set_contact_angle(b, contact_angle_deg);
  b.top_mm = flatten
                 ? static_cast<float>(puddle_thickness_mm(contact_angle_deg, capillary_length_mm))
                 : 0.0f;
  return b;
}

WaterBody cylinder_body(glm::vec2 centre, glm::vec2 axis, float half_width, float half_length,
                        double contact_angle_deg) {
  WaterBody b;
  b.u_mm = centre.x;
  b.v_mm = centre.y;
  b.axis_u = axis.x;
  b.axis_v = axis.y;
  b.side_mm = b.front_mm = b.back_mm = half_width;
  b.half_length_mm = half_length;
  set_contact_angle(b, contact_angle_deg);
  return b;
}

double cylinder_half_width_mm(double mass_mg, double length_mm, double contact_angle_deg) {
  // A circular segment meeting the glass at theta: its area is w^2 (theta - sin cos) / sin^2.
  const double q = std::clamp(contact_angle_deg, 1.0, kSteepestDeg) * M_PI / 180.0;
  const double s = std::sin(q);
  const double per_w2 = (q - s * std::cos(q)) / (s * s);
  return std::sqrt(std::max(mass_mg, 0.0) / (std::max(length_mm, 1e-6) * per_w2));
}

double body_reach_mm(const WaterBody& b) {
  return b.half_length_mm + std::max({b.side_mm, b.front_mm, b.back_mm});
}

void GlassWaterSurface::index(const GlassConfig& glass) {
  cells_u = std::max(1, static_cast<int>(std::ceil(glass.bottom_width_mm / kCellMm)));
  cells_v = std::max(1, static_cast<int>(std::ceil(glass.height_mm / kCellMm)));
  const std::size_t n_cells = static_cast<std::size_t>(cells_u) * cells_v;
  const float cell = static_cast<float>(kCellMm);
  const float half_diagonal = cell * std::sqrt(0.5f);
  // Every (cell, body) where the body's outline may reach the cell: the cells whose centre lies
  // within its widest reach of the body's centre line, and half a cell's diagonal more; and the
  // cells whose centre lies within a body's outline, wet. (Scratch kept by the thread: the step
  // publishes a surface a tick.)
  thread_local std::vector<std::uint64_t> pairs;
  thread_local std::vector<std::uint32_t> fill;
  thread_local std::vector<std::uint8_t> wet;
  pairs.clear();
  pairs.reserve(bodies.size() * 9);
  wet.assign(n_cells, 0);
  for (std::size_t k = 0; k < bodies.size(); ++k) {
    const WaterBody b = bodies[k];  // (a copy: the pushes below cannot alias it)
    const float wide = std::max({b.side_mm, b.front_mm, b.back_mm}) + half_diagonal;
    const float wide2 = wide * wide, half = b.half_length_mm;
    const float reach = half + wide;
    const int i0 = std::max(0, static_cast<int>((b.u_mm - reach) / cell));
    const int i1 = std::min(cells_u - 1, static_cast<int>((b.u_mm + reach) / cell));
    const int j0 = std::max(0, static_cast<int>((b.v_mm - reach) / cell));
    const int j1 = std::min(cells_v - 1, static_cast<int>((b.v_mm + reach) / cell));
    for (int j = j0; j <= j1; ++j) {
      const float dv = (static_cast<float>(j) + 0.5f) * cell - b.v_mm;
      for (int i = i0; i <= i1; ++i) {
        const float du = (static_cast<float>(i) + 0.5f) * cell - b.u_mm;
        // Beyond the centre segment's ends (x) and across it (y): body_rho2's frame.
        const float along = du * b.axis_u + dv * b.axis_v, y = dv * b.axis_u - du * b.axis_v;
        const float x = along - std::clamp(along, -half, half);
        if (x * x + y * y > wide2) continue;
        const int c = j * cells_u + i;
        pairs.push_back(static_cast<std::uint64_t>(c) << 32 | k);
        const float qx = x / (x >= 0.0f ? b.front_mm : b.back_mm), qy = y / b.side_mm;
        if (qx * qx + qy * qy < 1.0f) wet[static_cast<std::size_t>(c)] = 1;
      }
    }
  }
  // A counting sort by cell (the pairs of a cell keep their bodies' order).
  cells.assign(n_cells, 0);
  for (const std::uint64_t pair : pairs) ++cells[pair >> 32];
  std::uint32_t first = 0;
  constexpr std::uint32_t kMaxCount = (1u << kCountBits) - 1;
  fill.resize(n_cells);
  for (std::size_t c = 0; c < n_cells; ++c) {
    const std::uint32_t count = cells[c];
    fill[c] = first;
    cells[c] = first << kCountBits | std::min(count, kMaxCount);
    first += count;
  }
  entries.resize(pairs.size());
  for (const std::uint64_t pair : pairs)
    entries[fill[pair >> 32]++] = static_cast<std::uint32_t>(pair & 0xffffffffu);
  // The wet cells' centres over those within the glass's outline ([inset, width - inset] a row).
  std::size_t glass_cells = 0, wet_cells = 0;
  for (int j = 0; j < cells_v; ++j) {
    const double v = (j + 0.5) * kCellMm;
    if (v > glass.height_mm) break;
    const double inset = glass.inset_mm(v);
    const int first_i = std::max(0, static_cast<int>(std::ceil(inset / kCellMm - 0.5)));
    const int last_i = std::min(
        static_cast<int>(std::floor((glass.bottom_width_mm - inset) / kCellMm - 0.5)), cells_u - 1);
    if (last_i < first_i) continue;
    glass_cells += static_cast<std::size_t>(last_i - first_i + 1);
    const std::uint8_t* row = wet.data() + static_cast<std::size_t>(j) * cells_u;
    for (int i = first_i; i <= last_i; ++i) wet_cells += row[i];
  }
  wet_fraction =
      glass_cells ? static_cast<double>(wet_cells) / static_cast<double>(glass_cells) : 0.0;
}

namespace {

// The square of the fraction of the way out from a body's centre line to its outline through p
// (glass_surface.glsl's body_rho2).
float body_rho2(const WaterBody& b, glm::vec2 p) {
  const float du = p.x - b.u_mm, dv = p.y - b.v_mm;
  float x = du * b.axis_u + dv * b.axis_v;
  const float y = dv * b.axis_u - du * b.axis_v;
  x -= std::clamp(x, -b.half_length_mm, b.half_length_mm);
  const float qx = x / (x >= 0.0f ? b.front_mm : b.back_mm), qy = y / b.side_mm;
  return qx * qx + qy * qy;
}

}  // namespace

float GlassWaterSurface::top_height(glm::vec2 p) const {
  const int i = static_cast<int>(std::floor(p.x / kCellMm));
  const int j = static_cast<int>(std::floor(p.y / kCellMm));
  if (i < 0 || j < 0 || i >= cells_u || j >= cells_v) return 0.0f;
  const std::uint32_t listing = cells[static_cast<std::size_t>(j) * cells_u + i];
  const std::uint32_t first = listing >> kCountBits, count = listing & ((1u << kCountBits) - 1u);
  float highest = 0.0f;
  for (std::uint32_t e = first; e < first + count; ++e) {
    const WaterBody& b = bodies[entries[e]];
    highest = std::max(highest, b.side_mm * (1.0f - body_rho2(b, p)));
  }
  return highest;
}

std::shared_ptr<const GlassWaterSurface> surface_from_metaballs(
    const std::vector<Metaball>& metaballs, const GlassConfig& glass) {
  auto surface = std::make_shared<GlassWaterSurface>();
  surface->bodies.reserve(metaballs.size());
  for (const Metaball& m : metaballs) {
    if (m.radius_mm > 0.0f)
      surface->bodies.push_back(cap_body({m.u_mm, m.v_mm}, m.radius_mm, kContactAngleDeg));
  }
  surface->index(glass);
  return surface;
}

}  // namespace downpour::sim
