#include "server/sim/track.hpp"

#include <cmath>
#include <limits>
#include <numbers>

#include <glm/geometric.hpp>

namespace downpour::sim {
namespace {
constexpr double kCoarseStep = 5.0;
constexpr double kPi = std::numbers::pi;
}  // namespace

Track Track::test_track() {
  Track track;
  const double straight = 900.0;
  const double radius = 250.0;
  const double arc = kPi * radius;
  glm::dvec2 p(0.0, 0.0);
  double heading = 0.0;
  double s = 0.0;
  auto add = [&](double length, double curvature) {
    track.segments_.push_back({s, length, curvature, p, heading});
    s += length;
    track.length_ = s;
    p = glm::dvec2(track.at(s - 1e-9).position);
    heading += curvature * length;
  };
  add(straight, 0.0);
  add(arc, 1.0 / radius);
  add(straight, 0.0);
  add(arc, 1.0 / radius);
  track.length_ = s;
  // The crest sits on the back straight, which runs from s = straight + arc.
  track.crests_.push_back({straight + arc + straight * 0.5, 350.0, 10.0});
  for (double t = 0.0; t < track.length_; t += kCoarseStep) {
    track.coarse_samples_.push_back(glm::dvec2(track.at(t).position));
  }
  return track;
}

double Track::paved_half_width() const {
  return section_.lanes_each_way * section_.lane_width_m + section_.shoulder_m;
}

double Track::wrap(double s) const {
  const double w = std::fmod(s, length_);
  return w < 0.0 ? w + length_ : w;
}

double Track::elevation(double s) const {
  double z = 0.0;
  for (const Crest& c : crests_) {
    const double u = (wrap(s) - c.s_centre) / c.half_length;
    if (std::abs(u) < 1.0) z += c.height * 0.5 * (1.0 + std::cos(kPi * u));
  }
  return z;
}

double Track::elevation_grade(double s) const {
  double g = 0.0;
  for (const Crest& c : crests_) {
    const double u = (wrap(s) - c.s_centre) / c.half_length;
    if (std::abs(u) < 1.0) g += -c.height * 0.5 * kPi / c.half_length * std::sin(kPi * u);
  }
  return g;
}

TrackFrame Track::at(double s_in) const {
  const double s = wrap(s_in);
  const Segment* seg = &segments_.back();
  for (const Segment& candidate : segments_) {
    if (s < candidate.s0 + candidate.length) {
      seg = &candidate;
      break;
    }
  }
  const double d = s - seg->s0;
  TrackFrame f;
  glm::dvec2 xy;
  if (seg->curvature == 0.0) {
    f.heading_rad = seg->heading0;
    xy = seg->start + d * glm::dvec2(std::cos(seg->heading0), std::sin(seg->heading0));
  } else {
    const double r = 1.0 / seg->curvature;
    f.heading_rad = seg->heading0 + d * seg->curvature;
    // Centre of the circle lies to the left of the start heading for a left turn.
    const glm::dvec2 centre =
        seg->start + r * glm::dvec2(-std::sin(seg->heading0), std::cos(seg->heading0));
    xy = centre + r * glm::dvec2(std::sin(f.heading_rad), -std::cos(f.heading_rad));
  }
  f.position = glm::dvec3(xy, elevation(s));
  f.grade = elevation_grade(s);
  f.left = glm::dvec2(-std::sin(f.heading_rad), std::cos(f.heading_rad));
  return f;
}

double Track::surface_height(double s, double lateral) const {
  return elevation(s) + section_height(lateral);
}

double Track::section_height(double lateral) const {
  return -section_.crown_slope * std::min(std::abs(lateral), paved_half_width());
}

double Track::lane_centre(int lane) const { return -(lane + 0.5) * section_.lane_width_m; }

Track::Projection Track::project(glm::dvec2 xy, double fine_within_m) const {
  // Coarse search over the samples, then a fine search around the best one.
  std::size_t best = 0;
  double best_d2 = std::numeric_limits<double>::max();
  for (std::size_t i = 0; i < coarse_samples_.size(); ++i) {
    const glm::dvec2 d = coarse_samples_[i] - xy;
    const double d2 = glm::dot(d, d);
    if (d2 < best_d2) {
      best_d2 = d2;
      best = i;
    }
  }
  double best_s = best * kCoarseStep;
  if (best_d2 > fine_within_m * fine_within_m) {
    const TrackFrame f = at(best_s);
    return {wrap(best_s), glm::dot(xy - glm::dvec2(f.position), f.left)};
  }
  best_d2 = std::numeric_limits<double>::max();
  const double s_lo = best_s - kCoarseStep;
  for (double s = s_lo; s <= s_lo + 2.0 * kCoarseStep; s += 0.05) {
    const glm::dvec2 d = glm::dvec2(at(s).position) - xy;
    const double d2 = glm::dot(d, d);
    if (d2 < best_d2) {
      best_d2 = d2;
      best_s = s;
    }
  }
  const TrackFrame f = at(best_s);
  return {wrap(best_s), glm::dot(xy - glm::dvec2(f.position), f.left)};
}

Track::Projection Track::project_near(glm::dvec2 xy, double s) const {
  // The foot of the perpendicular: move s by the offset along the tangent until it vanishes (on a
  // curve of radius r, each step leaves an error of about lateral / r of the last).
  TrackFrame f = at(s);
  for (int i = 0; i < 4; ++i) {
    const glm::dvec2 tangent(f.left.y, -f.left.x);  // left is the tangent turned a quarter left
    const double along = glm::dot(xy - glm::dvec2(f.position), tangent);
    if (std::abs(along) < 1e-6) break;
    s += along;
    f = at(s);
  }
  const double loop = length();
  s = std::fmod(s, loop);
  if (s < 0.0) s += loop;
  return {s, glm::dot(xy - glm::dvec2(f.position), f.left)};
}

const Track& Track::built_in() {
  static const Track track = test_track();
  return track;
}

}  // namespace downpour::sim
