#include "server/sim/road_surface.hpp"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

#include "server/sim/random.hpp"

namespace downpour::sim {

namespace {

constexpr double kPi = 3.14159265358979323846;
// The seed's stream for the road's relief (random.hpp: each effect has its own).
constexpr std::uint64_t kReliefStream = 5;

double smoothstep(double t) { return t * t * (3.0 - 2.0 * t); }

}  // namespace

RoadSurface::RoadSurface(const Track& track, std::uint64_t seed)
    : RoadSurface(std::make_shared<const TrackRoads>(track), seed) {}

RoadSurface::RoadSurface(std::shared_ptr<const RoadNetwork> roads, std::uint64_t seed)
    : roads_(std::move(roads)) {
  RandomStream random(seed, kReliefStream);
  pieces_.resize(roads_->road_count());
  for (int r = 0; r < roads_->road_count(); ++r) {
    std::vector<double> starts = roads_->section_starts(r);
    const double length = roads_->road_length(r);
    for (std::size_t i = 0; i < starts.size(); ++i) {
      const double end = i + 1 < starts.size() ? starts[i + 1] : length;
      if (end > starts[i]) add_piece(r, starts[i], end, random);
    }
    if (pieces_[r].empty()) add_piece(r, 0.0, length, random);
  }
}

void RoadSurface::add_piece(int road, double s0, double s1, RandomStream& random) {
  Piece p;
  p.s0 = s0, p.s1 = s1;
  const LaneLayout layout = roads_->lanes(road, 0.5 * (s0 + s1));
  p.span = {layout.right(), layout.left()};
  for (const double s : {s0, s1}) {
    const PavedSpan end = roads_->paved(road, std::min(s, s1 - 1e-6));
    p.span_varies = p.span_varies || std::abs(end.left - p.span.left) > 0.01 ||
                    std::abs(end.right - p.span.right) > 0.01;
  }
  const double crown = layout.borders.empty() ? 0.0 : layout.borders[layout.centre];
  for (std::size_t lane = 0; lane < layout.driving.size(); ++lane) {
    const double width = layout.borders[lane + 1] - layout.borders[lane];
    if (!layout.driving[lane] || width < 2.0) continue;
    const double centre = 0.5 * (layout.borders[lane] + layout.borders[lane + 1]);
    p.wheel_paths.push_back(centre - kWheelPathOffsetM);
    p.wheel_paths.push_back(centre + kWheelPathOffsetM);
  }
  std::sort(p.wheel_paths.begin(), p.wheel_paths.end());
  const double length = s1 - s0;
  p.knots = std::max(1, static_cast<int>(std::ceil(length / kRutKnotM)));
  p.rut_depths.resize(p.wheel_paths.size() * p.knots);
  for (double& depth : p.rut_depths) depth = random.uniform(kRutMinDepthM, kRutMaxDepthM);
  // Traffic settles a road where its wheels run and where its edge has least support, not on the
  // crown's top: most bowls lie across a wheel path, the rest near the paved edge.
  p.buckets = std::max(1, static_cast<int>(std::ceil(length / kDepressionSpacingM)));
  p.depressions.resize(p.buckets);
  const double bucket_m = length / p.buckets;
  for (int b = 0; b < p.buckets; ++b) {
    const std::uint32_t count = random.poisson(1.0);
    for (std::uint32_t k = 0; k < count; ++k) {
      Depression d;
      d.s = s0 + (b + random.uniform()) * bucket_m;
      d.radius = random.uniform(kDepressionMinRadiusM, kDepressionMaxRadiusM);
      d.depth = random.uniform(kDepressionMinDepthM, kDepressionMaxDepthM);
      if (random.uniform() < 0.7 && !p.wheel_paths.empty()) {
        const auto path =
            std::min(static_cast<std::size_t>(random.uniform() * p.wheel_paths.size()),
                     p.wheel_paths.size() - 1);
        d.lateral = p.wheel_paths[path] + random.uniform(-0.6, 0.6);
      } else {
        const bool left = random.uniform() >= 0.5;
        d.lateral =
            left ? p.span.left - random.uniform(0.0, 1.5) : p.span.right + random.uniform(0.0, 1.5);
      }
      // Clear of the crown's top by kCrownClearM, and its centre on the paved width (none where
      // its side of the road has no room for it: a narrow or one-sided road). Kept a radius
      // inside the piece along the road, so that the next piece need not look back for it.
      const bool left = d.lateral >= crown;
      const double room = left ? p.span.left - crown : crown - p.span.right;
      const double clear = d.radius + kCrownClearM;
      if (room < clear) continue;
      const double from_crown = std::clamp(std::abs(d.lateral - crown), clear, room);
      d.lateral = crown + (left ? from_crown : -from_crown);
      if (!roads_->road_loops(road) && length > 2.0 * d.radius)
        d.s = std::clamp(d.s, s0 + d.radius, s1 - d.radius);
      p.depressions[b].push_back(d);
    }
  }
  pieces_[road].push_back(std::move(p));
}

const RoadSurface::Piece& RoadSurface::piece_at(int road, double s) const {
  const std::vector<Piece>& pieces = pieces_[road];
  const auto it = std::upper_bound(pieces.begin(), pieces.end(), s,
                                   [](double v, const Piece& p) { return v < p.s0; });
  return it == pieces.begin() ? pieces.front() : *std::prev(it);
}

bool RoadSurface::paved(const RoadPlace& place) const {
  if (place.road < 0 || place.road >= static_cast<int>(pieces_.size())) return false;
  const Piece& p = piece_at(place.road, place.s);
  return (p.span_varies ? roads_->paved(place.road, place.s) : p.span).contains(place.t);
}

double RoadSurface::rut_depth(const Piece& piece, bool loops, int path, double s) const {
  const double u = (s - piece.s0) / (piece.s1 - piece.s0) * piece.knots;
  const int k0 = std::clamp(static_cast<int>(u), 0, piece.knots - 1);
  const int k1 = loops ? (k0 + 1) % piece.knots : std::min(k0 + 1, piece.knots - 1);
  const double t = smoothstep(std::clamp(u - k0, 0.0, 1.0));
  const double* depths = &piece.rut_depths[static_cast<std::size_t>(path) * piece.knots];
  return depths[k0] + (depths[k1] - depths[k0]) * t;
}

double RoadSurface::relief(const RoadPlace& place) const {
  if (!paved(place)) return 0.0;
  const bool loops = roads_->road_loops(place.road);
  const double length = roads_->road_length(place.road);
  double s = place.s;
  if (loops) {
    s = std::fmod(s, length);
    if (s < 0.0) s += length;
  }
  const Piece& piece = piece_at(place.road, s);
  // A loop is one piece, whole (the built-in track's).
  const bool wraps = loops && piece.s0 == 0.0 && piece.s1 == length;
  const double lateral = place.t;
  double depth = 0.0;
  // Ruts: a cos^2 profile across each wheel path (they do not overlap: paths are > 1.4 m apart).
  for (std::size_t p = 0; p < piece.wheel_paths.size(); ++p) {
    const double u = (lateral - piece.wheel_paths[p]) / kRutHalfWidthM;
    if (std::abs(u) >= 1.0) continue;
    const double c = std::cos(0.5 * kPi * u);
    depth += rut_depth(piece, wraps, static_cast<int>(p), s) * c * c;
  }
  // Bowls: depth (1 - r^2)^2, smooth at the rim; those of this bucket and the two beside it
  // (a bowl is smaller than a bucket).
  const double span = piece.s1 - piece.s0;
  const int bucket =
      std::clamp(static_cast<int>((s - piece.s0) / span * piece.buckets), 0, piece.buckets - 1);
  for (int db = -1; db <= 1; ++db) {
    int b = bucket + db;
    if (wraps) {
      b = (b + piece.buckets) % piece.buckets;
    } else if (b < 0 || b >= piece.buckets) {
      continue;
    }
    for (const Depression& d : piece.depressions[b]) {
      double ds = s - d.s;
      if (wraps && ds > 0.5 * length) ds -= length;  // across the loop's start
      if (wraps && ds < -0.5 * length) ds += length;
      const double dl = lateral - d.lateral;
      const double r2 = (ds * ds + dl * dl) / (d.radius * d.radius);
      if (r2 >= 1.0) continue;
      depth += d.depth * (1.0 - r2) * (1.0 - r2);
    }
  }
  return -depth;
}

double RoadSurface::height_at(const RoadPlace& place) const {
  return roads_->surface_height(place) + relief(place);
}

double RoadSurface::height(glm::dvec2 xy) const { return height_at(roads_->project(xy, 30.0)); }

}  // namespace downpour::sim
