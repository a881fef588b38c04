// ASAM OpenDRIVE road networks (.xodr): what the simulators that feed the server describe their
// roads in (CARLA's to_opendrive(), esmini, VTD; SUMO's netconvert writes and reads it). Parsed
// from untrusted text within limits, into roads whose reference lines, lanes and profiles can be
// evaluated anywhere along them.
//
// Conventions, as the standard's: s the arc length along a road's reference line from its start;
// t lateral, positive to the left of the reference line's direction; headings counter-clockwise
// from the inertial frame's +x, in radians; heights in metres; superelevation a roll angle,
// positive when the road's right side is lower.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace downpour::road {

// A cubic in a local coordinate ds from its start s: a + b ds + c ds^2 + d ds^3.
struct Cubic {
  double s = 0.0;
  double a = 0.0, b = 0.0, c = 0.0, d = 0.0;
  double at(double ds) const { return a + ds * (b + ds * (c + ds * d)); }
  double slope(double ds) const { return b + ds * (2.0 * c + ds * 3.0 * d); }
};
// The value of a sequence of cubics (ordered by s) at s: the last one starting at or before it;
// 0 before the first, or none.
double eval_cubics(const std::vector<Cubic>& cubics, double s);
double eval_cubics_slope(const std::vector<Cubic>& cubics, double s);

// A point of a road's reference line.
struct RefPoint {
  double x = 0.0;
  double y = 0.0;
  double heading = 0.0;
};

// One <geometry> record of a plan view.
struct Geometry {
  enum class Kind { kLine, kArc, kSpiral, kPoly3, kParamPoly3 };
  Kind kind = Kind::kLine;
  double s = 0.0;  // start along the road
  double x = 0.0, y = 0.0, heading = 0.0;
  double length = 0.0;
  double curvature = 0.0;                         // arc
  double curv_start = 0.0, curv_end = 0.0;        // spiral
  double a = 0.0, b = 0.0, c = 0.0, d = 0.0;      // poly3: v(u)
  double au = 0.0, bu = 0.0, cu = 0.0, du = 0.0;  // paramPoly3: u(p)
  double av = 0.0, bv = 0.0, cv = 0.0, dv = 0.0;  // and v(p)
  bool p_normalized = true;                       // paramPoly3: p over [0, 1], else [0, length]
  // poly3 (as u(p) = p, v(p) its cubic) and paramPoly3: the parameter's end (where the arc length
  // reaches `length`, for poly3) and the arc length at knot_s.size() - 1 equal steps of it (built
  // when parsed), to find the parameter of an arc length.
  double p_end = 1.0;
  std::vector<double> knot_s;

  // The point at ds along this record (clamped to [0, length]).
  RefPoint at(double ds) const;
};

struct RoadMark {
  double s_offset = 0.0;  // from the lane section's start
  std::string type;       // solid, broken, solid solid, none, ...
  std::string colour;     // standard, white, yellow, ...
  double width = 0.12;    // metres
};

// A lane's surface raised over the road's (superelevated) reference plane, at its inner and outer
// borders, linear between them: a crowned road's fall towards its edges, a raised sidewalk.
struct LaneHeight {
  double s_offset = 0.0;  // from the lane section's start
  double inner = 0.0;
  double outer = 0.0;
};

struct Lane {
  int id = 0;                 // > 0 left of the centre lane, < 0 right, 0 the centre lane itself
  std::string type;           // driving, shoulder, border, sidewalk, median, ...
  std::vector<Cubic> widths;  // s: offset from the lane section's start
  std::vector<LaneHeight> heights;
  std::vector<RoadMark> marks;
  // The lane's own links, where given (0: none).
  int predecessor = 0, successor = 0;
};

struct LaneSection {
  double s = 0.0;
  std::vector<Lane> left;   // ids 1, 2, ... outwards
  Lane centre;              // id 0 (width none; its road mark the centre line's)
  std::vector<Lane> right;  // ids -1, -2, ... outwards
};

struct RoadLink {
  enum class Type { kNone, kRoad, kJunction };
  Type type = Type::kNone;
  std::string id;
  bool contact_end = false;  // contactPoint="end" (a road link), else its start
};

struct Road {
  std::string id;
  std::string name;
  std::string junction = "-1";  // the junction this road connects within, or "-1"
  double length = 0.0;
  RoadLink predecessor, successor;
  std::vector<Geometry> plan_view;
  std::vector<Cubic> elevation;       // height of the reference line over s
  std::vector<Cubic> superelevation;  // roll angle, radians
  std::vector<Cubic> lane_offsets;    // the centre lane's offset from the reference line
  std::vector<LaneSection> sections;

  RefPoint reference(double s) const;
  double height(double s) const { return eval_cubics(elevation, s); }
  double roll(double s) const { return eval_cubics(superelevation, s); }
  double lane_offset(double s) const { return eval_cubics(lane_offsets, s); }
  const LaneSection& section_at(double s) const;  // requires sections non-empty
  // The lateral offset of a lane's outer border at s (t of the side it is on: left lanes' t
  // grows, right lanes' falls), from the centre lane's offset outwards; 0 for lane 0 is the centre
  // lane's offset itself. Lanes missing from the section at s count zero width.
  double lane_border(double s, int lane_id) const;
  // The height of the road surface at (s, t): the reference line's elevation tilted by the
  // superelevation about it, and the lane's height there (beyond the outermost lane, its outer
  // border's).
  double surface_height(double s, double t) const;
};

struct JunctionConnection {
  std::string id;
  std::string incoming_road;
  std::string connecting_road;
  bool contact_end = false;
  std::vector<std::pair<int, int>> lane_links;  // from (incoming), to (connecting)
};

struct Junction {
  std::string id;
  std::string name;
  std::vector<JunctionConnection> connections;
};

struct Network {
  std::string name;
  int rev_major = 1, rev_minor = 0;
  std::vector<Road> roads;
  std::vector<Junction> junctions;

  const Road* find_road(std::string_view id) const;
};

// How much a parsed file may hold: a hostile or broken file is refused before it costs memory or
// time out of proportion.
struct Limits {
  std::size_t max_bytes = 64u << 20;  // the XML text
  std::size_t max_roads = 20000;
  std::size_t max_records = 2'000'000;  // geometry, lane, width, mark and profile records in all
  std::size_t max_lanes_per_side = 32;
  double max_road_length_m = 100'000.0;
  // All roads' together: the scene built from them (a mesh row every few metres) is in proportion.
  double max_total_length_m = 200'000.0;
  double max_coordinate_m = 1e7;  // |x|, |y|
  // Any number at all (so that a cubic over a road's length stays finite).
  double max_number = 1e9;
  double max_curvature = 1.0;  // 1/m: a 1 m radius, far sharper than any road's
  // Poly3 and paramPoly3 records' arc-length samples (a knot every half metre, 16 to 4096 a
  // record), in all.
  std::size_t max_curve_knots = 4'000'000;
};

// A file refused: the element and the line of the text it is on (1-based; 0 when the text is not
// XML at all), and what is wrong.
class ParseError : public std::runtime_error {
 public:
  ParseError(std::string element, int line, const std::string& what);
  const std::string& element() const { return element_; }
  int line() const { return line_; }

 private:
  std::string element_;
  int line_ = 0;
};

// Parses OpenDRIVE XML text. Throws ParseError.
Network parse_opendrive(std::string_view xml, const Limits& limits = {});

}  // namespace downpour::road
