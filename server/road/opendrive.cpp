// The road model's evaluation: the reference line's records (lines, arcs, spirals, poly3 and
// paramPoly3) at an arc length, the lanes' borders and the road's surface. The parser that builds
// the model is opendrive_parse.cpp.
#include "server/road/opendrive.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "server/road/fresnel.hpp"
#include "server/road/opendrive_curve.hpp"

namespace downpour::road {
namespace {

// --- numbers along curves --------------------------------------------------------------------

// The heading-relative point of an arc of curvature k at ds (a line for k = 0).
RefPoint arc_local(double k, double ds) {
  if (std::abs(k) < 1e-12) return {ds, 0.0, 0.0};
  const double a = k * ds;
  return {std::sin(a) / k, (1.0 - std::cos(a)) / k, a};
}

// The heading-relative point of a clothoid record at ds: its curvature from k0 by `rate` per
// metre. Through the Fresnel integrals (the standard clothoid whose curvature passes k0 at
// s0 = k0 / rate); where that clothoid is so wide that its coordinates would swamp the piece
// (a rate under some 3e-10 / m^2), by quadrature of the heading instead.
RefPoint spiral_local(double k0, double rate, double ds) {
  if (rate == 0.0 || !std::isfinite(rate)) return arc_local(k0, ds);
  if (std::sqrt(std::numbers::pi / std::abs(rate)) > 1e5) {
    const auto heading = [&](double u) { return u * (k0 + 0.5 * rate * u); };
    // A piece per 0.1 rad of turn and per 50 m, at most 512 (a file's coil of a road gets a
    // rougher answer, not a longer wait).
    const double turn = std::abs(k0) * ds + 0.5 * std::abs(rate) * ds * ds;
    const int pieces = static_cast<int>(std::clamp(std::ceil(turn / 0.1 + ds / 50.0), 1.0, 512.0));
    double x = 0.0, y = 0.0;
    for (int i = 0; i < pieces; ++i) {
      const double a = ds * i / pieces, b = ds * (i + 1) / pieces;
      x += gauss5([&](double u) { return std::cos(heading(u)); }, a, b);
      y += gauss5([&](double u) { return std::sin(heading(u)); }, a, b);
    }
    return {x, y, heading(ds)};
  }
  const double s0 = k0 / rate;
  const ClothoidPoint p0 = standard_clothoid(rate, s0);
  const ClothoidPoint p1 = standard_clothoid(rate, s0 + ds);
  const double dx = p1.x - p0.x, dy = p1.y - p0.y;
  const double c = std::cos(-p0.heading), s = std::sin(-p0.heading);
  return {c * dx - s * dy, s * dx + c * dy, p1.heading - p0.heading};
}

}  // namespace

// The parameter of a poly3 / paramPoly3 record at arc length ds: the knot interval by search,
// then Newton's steps on the arc length within it.
double param_at(const Geometry& g, double ds) {
  const LocalCurve curve{g};
  const std::size_t n = g.knot_s.size() - 1;
  const double step = g.p_end / static_cast<double>(n);
  const auto it = std::upper_bound(g.knot_s.begin(), g.knot_s.end(), ds);
  const std::size_t k = std::min(n - 1, static_cast<std::size_t>(std::max<std::ptrdiff_t>(
                                            0, std::distance(g.knot_s.begin(), it) - 1)));
  const double p0 = step * static_cast<double>(k);
  const double s0 = g.knot_s[k], s1 = g.knot_s[k + 1];
  double p = p0 + step * (s1 > s0 ? std::clamp((ds - s0) / (s1 - s0), 0.0, 1.0) : 0.0);
  for (int i = 0; i < 3; ++i) {
    const double speed = curve.speed(p);
    if (speed <= 1e-12) break;
    p = std::clamp(p - (s0 + curve.arc(p0, p) - ds) / speed, p0, p0 + step);
  }
  return p;
}

namespace {

// The last cubic starting at or before s, if any.
const Cubic* cubic_at(const std::vector<Cubic>& cubics, double s) {
  const auto it = std::upper_bound(cubics.begin(), cubics.end(), s,
                                   [](double v, const Cubic& c) { return v < c.s; });
  return it == cubics.begin() ? nullptr : &*std::prev(it);
}

}  // namespace

double eval_cubics(const std::vector<Cubic>& cubics, double s) {
  const Cubic* c = cubic_at(cubics, s);
  return c ? c->at(s - c->s) : 0.0;
}

double eval_cubics_slope(const std::vector<Cubic>& cubics, double s) {
  const Cubic* c = cubic_at(cubics, s);
  return c ? c->slope(s - c->s) : 0.0;
}

RefPoint Geometry::at(double ds) const {
  ds = std::clamp(ds, 0.0, length);
  RefPoint local;  // relative to the record's start, heading along +x
  switch (kind) {
    case Kind::kLine:
      local = {ds, 0.0, 0.0};
      break;
    case Kind::kArc:
      local = arc_local(curvature, ds);
      break;
    case Kind::kSpiral:
      // (A record too short to turn in is its start's arc.)
      local = spiral_local(curv_start, length > 1e-6 ? (curv_end - curv_start) / length : 0.0, ds);
      break;
    case Kind::kPoly3:
    case Kind::kParamPoly3: {
      const LocalCurve curve{*this};
      const double p = knot_s.size() >= 2 ? param_at(*this, ds) : 0.0;
      local = {curve.u(p), curve.v(p), std::atan2(curve.dv(p), curve.du(p))};
      break;
    }
  }
  const double c = std::cos(heading), s = std::sin(heading);
  return {x + c * local.x - s * local.y, y + s * local.x + c * local.y, heading + local.heading};
}

RefPoint Road::reference(double s) const {
  if (plan_view.empty()) return {};
  const auto it = std::upper_bound(plan_view.begin(), plan_view.end(), s,
                                   [](double v, const Geometry& g) { return v < g.s; });
  const Geometry& g = it == plan_view.begin() ? plan_view.front() : *std::prev(it);
  return g.at(s - g.s);
}

const LaneSection& Road::section_at(double s) const {
  const auto it = std::upper_bound(sections.begin(), sections.end(), s,
                                   [](double v, const LaneSection& l) { return v < l.s; });
  return it == sections.begin() ? sections.front() : *std::prev(it);
}

double Road::lane_border(double s, int lane_id) const {
  double t = lane_offset(s);
  if (lane_id == 0 || sections.empty()) return t;
  const LaneSection& section = section_at(s);
  const std::vector<Lane>& side = lane_id > 0 ? section.left : section.right;
  const double sign = lane_id > 0 ? 1.0 : -1.0;
  const auto count = static_cast<std::size_t>(std::abs(lane_id));
  for (std::size_t i = 0; i < std::min(count, side.size()); ++i) {
    t += sign * std::max(0.0, eval_cubics(side[i].widths, s - section.s));
  }
  return t;
}

double Road::surface_height(double s, double t) const {
  double z = height(s) + t * std::tan(roll(s));
  if (sections.empty()) return z;
  const LaneSection& section = section_at(s);
  const double ds = s - section.s;
  const std::vector<Lane>& side = t >= lane_offset(s) ? section.left : section.right;
  const int sign = t >= lane_offset(s) ? 1 : -1;
  // The lane t lies in, from the centre outwards (or the outermost one).
  double inner = lane_offset(s);
  for (std::size_t i = 0; i < side.size(); ++i) {
    const double outer = lane_border(s, sign * static_cast<int>(i + 1));
    const bool last = i + 1 == side.size();
    if (!last && (t - outer) * sign > 0.0) {
      inner = outer;
      continue;
    }
    const auto& heights = side[i].heights;
    const auto it = std::upper_bound(heights.begin(), heights.end(), ds,
                                     [](double v, const LaneHeight& h) { return v < h.s_offset; });
    if (it == heights.begin()) break;
    const LaneHeight& h = *std::prev(it);
    const double width = std::abs(outer - inner);
    const double f = width > 1e-9 ? std::clamp(std::abs(t - inner) / width, 0.0, 1.0) : 1.0;
    z += h.inner + (h.outer - h.inner) * f;
    break;
  }
  return z;
}

const Road* Network::find_road(std::string_view id) const {
  for (const Road& r : roads) {
    if (r.id == id) return &r;
  }
  return nullptr;
}

}  // namespace downpour::road
