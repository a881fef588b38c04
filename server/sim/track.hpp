// The built-in test track: a closed centreline (straights, curves, a hill crest) with a crowned
// multi-lane cross-section. Geometry only; the road mesh and the scenarios are built from it.
#pragma once

#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace downpour::sim {

struct TrackFrame {
  glm::dvec3 position{0.0};   // centreline point, world frame
  double heading_rad = 0.0;   // direction of travel, counter-clockwise from +x
  double grade = 0.0;         // dz/ds along the centreline
  glm::dvec2 left{0.0, 1.0};  // unit vector to the left of the direction of travel (horizontal)
};

struct CrossSection {
  double lane_width_m = 3.5;
  int lanes_each_way = 2;
  double shoulder_m = 1.5;
  double crown_slope = 0.02;  // fall from the centreline to each edge, per metre
};

class Track {
 public:
  // About 3.4 km: two 900 m straights joined by two 250 m radius half circles; a 10 m crest on the
  // back straight.
  static Track test_track();
  // The same, made once and shared (sessions, the renderer's stats, test fixtures).
  static const Track& built_in();

  // The centreline's pieces, in order around the loop: straights and arcs.
  struct Segment {
    double s0 = 0.0;
    double length = 0.0;
    double curvature = 0.0;  // 1/m, left positive; 0 = straight
    glm::dvec2 start{0.0};
    double heading0 = 0.0;
  };
  // Hills: z = height (1 + cos(pi u)) / 2, u = (s - s_centre) / half_length in (-1, 1).
  struct Crest {
    double s_centre = 0.0;
    double half_length = 0.0;
    double height = 0.0;
  };
  const std::vector<Segment>& segments() const { return segments_; }
  const std::vector<Crest>& crests() const { return crests_; }

  double length() const { return length_; }
  const CrossSection& cross_section() const { return section_; }
  double paved_half_width() const;  // lanes and shoulders

  // s wraps around the loop.
  TrackFrame at(double s) const;
  // Road surface height at lateral offset (left positive) from the centreline: the crowned section.
  double surface_height(double s, double lateral) const;
  // The crowned section's height at a lateral offset, relative to the centreline's.
  double section_height(double lateral) const;
  // Lateral offset of the centre of lane i on the side of travel (0 = the inner lane next to the
  // centreline, growing outwards); negative = right of the centreline as driven forwards.
  double lane_centre(int lane) const;

  struct Projection {
    double s = 0.0;
    double lateral = 0.0;  // signed, left positive
  };
  // Nearest centreline point of a horizontal position, to a few centimetres; beyond fine_within_m
  // from the centreline the answer is only as good as a 5 m sampling (cheaper, for scenery).
  Projection project(glm::dvec2 xy, double fine_within_m = 1e30) const;
  // The same near the centreline point s_guess (within a few metres along it, as a neighbouring
  // position's): a few Newton steps from the guess, much cheaper than a search of the whole track.
  Projection project_near(glm::dvec2 xy, double s_guess) const;

 private:
  double wrap(double s) const;
  double elevation(double s) const;
  double elevation_grade(double s) const;

  std::vector<Segment> segments_;
  std::vector<Crest> crests_;
  std::vector<glm::dvec2> coarse_samples_;  // every kCoarseStep metres, for project()
  CrossSection section_;
  double length_ = 0.0;
};

}  // namespace downpour::sim
