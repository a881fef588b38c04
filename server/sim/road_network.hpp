// The roads a session drives on, as the simulation and the renderer see them: one or more roads,
// each a reference line with lanes across it, found from a world position and evaluated at a
// place on it. The built-in track is one looping road (TrackRoads); an OpenDRIVE file is many
// (opendrive_roads.hpp). Places are (road, s, t): s along the road's reference line, t lateral,
// left positive, in metres. No GL.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <glm/vec2.hpp>

#include "server/sim/track.hpp"
#include "server/sim/types.hpp"

namespace downpour::sim {

struct RoadPlace {
  int road = 0;
  double s = 0.0;
  double t = 0.0;  // left positive
};

// A painted line along a lane border.
struct LaneMark {
  enum class Kind : std::uint8_t {
    kNone,
    kSolid,
    kBroken,       // 3 m painted, 9 m gap
    kSolidSolid,   // two lines, each `width_m` wide, their centres `spacing_m` apart
    kSolidBroken,  // the first (right) solid, the second (left) broken
    kBrokenSolid,
    kBrokenBroken,
  };
  Kind kind = Kind::kNone;
  double width_m = 0.12;   // one line's
  double offset_m = 0.0;   // of the mark's centre from the border, away from the centre lane
  double spacing_m = 0.3;  // a double line's
  bool yellow = false;
};

// A road's lanes across at one s: the borders from its right edge to its left (t increasing),
// among them the centre lane's (OpenDRIVE's lane 0, where the two directions meet).
struct LaneLayout {
  std::vector<double> borders;        // t, increasing
  std::vector<LaneMark> marks;        // one a border
  std::vector<std::uint8_t> driving;  // one a lane (borders i to i + 1): 1 where cars drive
  int centre = 0;                     // the centre lane's border's index
  double right() const { return borders.empty() ? 0.0 : borders.front(); }
  double left() const { return borders.empty() ? 0.0 : borders.back(); }
};

// The paved width across at one s: every lane's, shoulders and all.
struct PavedSpan {
  double right = 0.0;  // t, <= 0 mostly
  double left = 0.0;
  bool contains(double t) const { return t >= right && t <= left; }
};

class RoadNetwork {
 public:
  virtual ~RoadNetwork() = default;

  virtual int road_count() const = 0;
  virtual std::string road_id(int road) const = 0;
  virtual double road_length(int road) const = 0;
  // Whether s wraps around (the built-in track's loop).
  virtual bool road_loops(int road) const = 0;
  // Whether a road only connects others within a junction (no street lights of its own).
  virtual bool connecting(int road) const = 0;
  // Where a road's lanes may change: its lane sections' starts, the first 0.
  virtual std::vector<double> section_starts(int road) const = 0;

  // The reference line at s: position (with the elevation), heading, grade, left.
  virtual TrackFrame frame(int road, double s) const = 0;
  // The road surface's height at a place, without relief: the elevation, crown, superelevation and
  // lane heights; beyond the paved width, its edge's.
  virtual double surface_height(const RoadPlace& place) const = 0;
  virtual PavedSpan paved(int road, double s) const = 0;
  virtual LaneLayout lanes(int road, double s) const = 0;

  // The place of a horizontal position: on the road whose paved width holds it (where roads
  // overlap, as in a junction, the one whose edge is furthest), or else the nearest edge's road.
  // Beyond fine_within_m of every road the answer may be only as good as a few metres' sampling
  // (cheaper, for scenery).
  virtual RoadPlace project(glm::dvec2 xy, double fine_within_m = 1e30) const = 0;
  // The same, starting from a place a few metres away (a neighbouring position's): much cheaper.
  // A place on no road may get scenery's answer (an OpenDRIVE network's, beyond 30 m of a road).
  virtual RoadPlace project_near(glm::dvec2 xy, const RoadPlace& guess) const = 0;

  // The roads' extent in x and y, paved widths included.
  virtual void bounds(glm::dvec2& lo, glm::dvec2& hi) const = 0;
  // Whether the scenery around may be hills of its own: the built-in track's may; a simulator's
  // roads are among its own scenery, which the ground must not rise through (a car between two
  // roads stays above it), so the ground follows the nearest road's level.
  virtual bool own_scenery() const { return false; }
};

// The built-in track as a network of one looping road (the track must outlive it).
class TrackRoads final : public RoadNetwork {
 public:
  explicit TrackRoads(const Track& track);
  const Track& track() const { return track_; }

  int road_count() const override { return 1; }
  std::string road_id(int) const override { return "track"; }
  double road_length(int) const override { return track_.length(); }
  bool road_loops(int) const override { return true; }
  bool connecting(int) const override { return false; }
  bool own_scenery() const override { return true; }
  std::vector<double> section_starts(int) const override { return {0.0}; }
  TrackFrame frame(int, double s) const override { return track_.at(s); }
  double surface_height(const RoadPlace& p) const override {
    return track_.surface_height(p.s, p.t);
  }
  PavedSpan paved(int, double) const override {
    return {-track_.paved_half_width(), track_.paved_half_width()};
  }
  LaneLayout lanes(int road, double s) const override;
  RoadPlace project(glm::dvec2 xy, double fine_within_m = 1e30) const override;
  RoadPlace project_near(glm::dvec2 xy, const RoadPlace& guess) const override;
  void bounds(glm::dvec2& lo, glm::dvec2& hi) const override { lo = lo_, hi = hi_; }

 private:
  const Track& track_;
  glm::dvec2 lo_{0.0}, hi_{0.0};
};

// The place of a horizontal position on the roads, with its lane (EgoPlace, types.hpp).
EgoPlace ego_place(const RoadNetwork& roads, glm::dvec2 xy);

// The built-in track's network, made once.
const std::shared_ptr<const RoadNetwork>& built_in_roads();

}  // namespace downpour::sim
