// The OpenDRIVE parser: untrusted XML (pugixml) into a road Network, within Limits, each refusal
// a ParseError naming the element and its line. The model it builds is evaluated in opendrive.cpp.
#include "server/road/opendrive.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <set>
#include <string>
#include <system_error>

#include <pugixml.hpp>

#include "server/road/opendrive_curve.hpp"

namespace downpour::road {

ParseError::ParseError(std::string element, int line, const std::string& what)
    : std::runtime_error("OpenDRIVE: <" + element + "> at line " + std::to_string(line) + ": " +
                         what),
      element_(std::move(element)),
      line_(line) {}

// --- the parser --------------------------------------------------------------------------------

namespace {

class Parser {
 public:
  Parser(std::string_view text, const Limits& limits) : text_(text), limits_(limits) {}

  Network parse() {
    if (text_.size() > limits_.max_bytes) {
      throw ParseError("OpenDRIVE", 0,
                       "the file is " + std::to_string(text_.size()) +
                           " bytes, over the limit of " + std::to_string(limits_.max_bytes));
    }
    pugi::xml_document doc;
    const pugi::xml_parse_result result =
        doc.load_buffer(text_.data(), text_.size(), pugi::parse_default, pugi::encoding_utf8);
    if (!result) {
      throw ParseError("OpenDRIVE", line_of(result.offset),
                       std::string("not well-formed XML: ") + result.description());
    }
    const pugi::xml_node root = doc.child("OpenDRIVE");
    if (!root) throw ParseError("OpenDRIVE", 1, "no <OpenDRIVE> root element");
    Network net;
    if (const pugi::xml_node header = root.child("header")) {
      net.name = header.attribute("name").as_string();
      if (header.attribute("revMajor")) net.rev_major = integer(header, "revMajor");
      if (header.attribute("revMinor")) net.rev_minor = integer(header, "revMinor");
    }
    std::set<std::string> road_ids;
    for (const pugi::xml_node road : root.children("road")) {
      if (net.roads.size() >= limits_.max_roads) {
        fail(road, "more than " + std::to_string(limits_.max_roads) + " roads");
      }
      net.roads.push_back(parse_road(road));
      if (!road_ids.insert(net.roads.back().id).second) {
        fail(road, "a second road with id \"" + net.roads.back().id + "\"");
      }
    }
    if (net.roads.empty()) throw ParseError("OpenDRIVE", line_of(root), "no <road> elements");
    for (const pugi::xml_node junction : root.children("junction")) {
      net.junctions.push_back(parse_junction(junction, road_ids));
    }
    return net;
  }

 private:
  [[noreturn]] void fail(const pugi::xml_node& node, const std::string& what) const {
    throw ParseError(node.name(), line_of(node), what);
  }

  int line_of(const pugi::xml_node& node) const { return line_of(node.offset_debug()); }
  int line_of(std::ptrdiff_t offset) const {
    if (offset < 0) return 0;
    const std::size_t end = std::min(static_cast<std::size_t>(offset), text_.size());
    return 1 + static_cast<int>(std::count(text_.begin(), text_.begin() + end, '\n'));
  }

  void count_record(const pugi::xml_node& node) {
    if (++records_ > limits_.max_records) {
      fail(node, "more than " + std::to_string(limits_.max_records) + " records in the file");
    }
  }

  // A finite number; `fallback` where the attribute is absent (NaN: it is required).
  double number(const pugi::xml_node& node, const char* name, double fallback = std::nan("")) {
    const pugi::xml_attribute attr = node.attribute(name);
    if (!attr) {
      if (std::isnan(fallback)) fail(node, std::string("attribute ") + name + " is missing");
      return fallback;
    }
    const char* begin = attr.value();
    const char* end = begin + std::strlen(begin);
    while (begin < end && std::isspace(static_cast<unsigned char>(*begin))) ++begin;
    while (end > begin && std::isspace(static_cast<unsigned char>(end[-1]))) --end;
    if (begin < end && *begin == '+') ++begin;
    double value = 0.0;
    const auto [ptr, ec] = std::from_chars(begin, end, value);
    if (ec != std::errc() || ptr != end || begin == end || !std::isfinite(value)) {
      fail(node,
           std::string("attribute ") + name + "=\"" + attr.value() + "\" is not a finite number");
    }
    if (std::abs(value) > limits_.max_number) {
      fail(node, std::string("attribute ") + name + "=\"" + attr.value() + "\" is beyond " +
                     std::to_string(limits_.max_number));
    }
    return value;
  }
  // A whole number within +-1e6 (lane ids and the like).
  int integer(const pugi::xml_node& node, const char* name) {
    const double v = number(node, name);
    if (v != std::floor(v) || std::abs(v) > 1e6) {
      fail(node, std::string("attribute ") + name + " is not a whole number within 1e6");
    }
    return static_cast<int>(v);
  }
  double coordinate(const pugi::xml_node& node, const char* name) {
    const double v = number(node, name);
    if (std::abs(v) > limits_.max_coordinate_m) {
      fail(node, std::string("attribute ") + name + " is beyond " +
                     std::to_string(limits_.max_coordinate_m) + " m");
    }
    return v;
  }
  double curvature(const pugi::xml_node& node, const char* name) {
    const double v = number(node, name);
    if (std::abs(v) > limits_.max_curvature) {
      fail(node, std::string("attribute ") + name + " is sharper than " +
                     std::to_string(limits_.max_curvature) + " per metre");
    }
    return v;
  }
  double non_negative(const pugi::xml_node& node, const char* name,
                      double fallback = std::nan("")) {
    const double v = number(node, name, fallback);
    if (v < 0.0) fail(node, std::string("attribute ") + name + " is negative");
    return v;
  }

  Cubic cubic(const pugi::xml_node& node, const char* s_name) {
    count_record(node);
    Cubic c;
    c.s = non_negative(node, s_name);
    c.a = number(node, "a");
    c.b = number(node, "b");
    c.c = number(node, "c");
    c.d = number(node, "d");
    return c;
  }
  // Cubics of the named children, in s order (as the standard wants; a file that does not is
  // refused rather than guessed at).
  std::vector<Cubic> cubics(const pugi::xml_node& parent, const char* child, const char* s_name) {
    std::vector<Cubic> out;
    for (const pugi::xml_node n : parent.children(child)) {
      out.push_back(cubic(n, s_name));
      if (out.size() > 1 && out.back().s < out[out.size() - 2].s) {
        fail(n, std::string(s_name) + " goes backwards");
      }
    }
    return out;
  }

  RoadLink link(const pugi::xml_node& node) {
    RoadLink l;
    if (!node) return l;
    const std::string type = node.attribute("elementType").as_string("road");
    if (type == "road") {
      l.type = RoadLink::Type::kRoad;
    } else if (type == "junction") {
      l.type = RoadLink::Type::kJunction;
    } else {
      fail(node, "elementType \"" + type + "\" is neither road nor junction");
    }
    l.id = node.attribute("elementId").as_string();
    if (l.id.empty()) fail(node, "attribute elementId is missing");
    l.contact_end = std::string_view(node.attribute("contactPoint").as_string()) == "end";
    return l;
  }

  void parse_geometry(const pugi::xml_node& node, Road& road) {
    count_record(node);
    Geometry g;
    g.s = non_negative(node, "s");
    g.x = coordinate(node, "x");
    g.y = coordinate(node, "y");
    g.heading = number(node, "hdg");
    g.length = non_negative(node, "length");
    // (Files round their lengths: a metre or a thousandth of the road's over is let pass.)
    const double slack = std::max(1.0, 1e-3 * road.length);
    if (g.s + g.length > road.length + slack) fail(node, "runs beyond its road's length");
    int kinds = 0;
    for (const pugi::xml_node shape : node.children()) {
      const std::string_view name = shape.name();
      if (name == "line") {
        g.kind = Geometry::Kind::kLine;
      } else if (name == "arc") {
        g.kind = Geometry::Kind::kArc;
        g.curvature = curvature(shape, "curvature");
      } else if (name == "spiral") {
        g.kind = Geometry::Kind::kSpiral;
        g.curv_start = curvature(shape, "curvStart");
        g.curv_end = curvature(shape, "curvEnd");
      } else if (name == "poly3") {
        g.kind = Geometry::Kind::kPoly3;
        g.au = 0.0, g.bu = 1.0, g.cu = 0.0, g.du = 0.0;
        g.av = number(shape, "a"), g.bv = number(shape, "b");
        g.cv = number(shape, "c"), g.dv = number(shape, "d");
        g.a = g.av, g.b = g.bv, g.c = g.cv, g.d = g.dv;
      } else if (name == "paramPoly3") {
        g.kind = Geometry::Kind::kParamPoly3;
        g.au = number(shape, "aU"), g.bu = number(shape, "bU");
        g.cu = number(shape, "cU"), g.du = number(shape, "dU");
        g.av = number(shape, "aV"), g.bv = number(shape, "bV");
        g.cv = number(shape, "cV"), g.dv = number(shape, "dV");
        const std::string range = shape.attribute("pRange").as_string("normalized");
        if (range != "normalized" && range != "arcLength") {
          fail(shape, "pRange \"" + range + "\" is neither normalized nor arcLength");
        }
        g.p_normalized = range == "normalized";
      } else {
        continue;  // userData and the like
      }
      ++kinds;
    }
    if (kinds != 1) fail(node, "needs exactly one of line, arc, spiral, poly3, paramPoly3");
    if (g.kind == Geometry::Kind::kPoly3 || g.kind == Geometry::Kind::kParamPoly3) {
      build_knots(node, g);
    }
    if (!road.plan_view.empty() && g.s < road.plan_view.back().s) fail(node, "s goes backwards");
    road.plan_view.push_back(std::move(g));
  }

  // The arc length table of a poly3 / paramPoly3 record, a knot every half metre of its length
  // (16 to 4096). A poly3's parameter u ends where its arc length reaches the record's length:
  // the arc grows at least as fast as u, so by u = length at the latest; a first table over
  // [0, length] finds that end, a second one covers [0, end].
  void build_knots(const pugi::xml_node& node, Geometry& g) {
    const LocalCurve curve{g};
    const auto n = static_cast<std::size_t>(std::clamp(g.length / 0.5, 16.0, 4096.0));
    const auto table = [&](double p_end) {
      knots_ += n + 1;
      if (knots_ > limits_.max_curve_knots) {
        fail(node, "the file's curves need more than " + std::to_string(limits_.max_curve_knots) +
                       " samples in all");
      }
      g.p_end = p_end;
      g.knot_s.assign(n + 1, 0.0);
      for (std::size_t k = 0; k < n; ++k) {
        const double p0 = p_end * static_cast<double>(k) / static_cast<double>(n);
        const double p1 = p_end * static_cast<double>(k + 1) / static_cast<double>(n);
        g.knot_s[k + 1] = g.knot_s[k] + curve.arc(p0, p1);
      }
      if (!std::isfinite(g.knot_s.back())) fail(node, "its curve's length is not finite");
    };
    if (g.kind == Geometry::Kind::kPoly3) {
      table(g.length);
      table(param_at(g, g.length));
    } else {
      table(g.p_normalized ? 1.0 : g.length);
    }
    if (g.length > 0.0 && g.knot_s.back() <= 0.0) fail(node, "its curve has no length");
  }

  Lane parse_lane(const pugi::xml_node& node) {
    count_record(node);
    Lane lane;
    lane.id = integer(node, "id");
    lane.type = node.attribute("type").as_string("none");
    if (const pugi::xml_node l = node.child("link")) {
      if (const pugi::xml_node p = l.child("predecessor")) lane.predecessor = integer(p, "id");
      if (const pugi::xml_node s = l.child("successor")) lane.successor = integer(s, "id");
    }
    if (node.child("border"))
      fail(node.child("border"), "lane borders are not supported (widths are)");
    lane.widths = cubics(node, "width", "sOffset");
    for (const pugi::xml_node h : node.children("height")) {
      count_record(h);
      LaneHeight height;
      height.s_offset = non_negative(h, "sOffset", 0.0);
      height.inner = number(h, "inner", 0.0);
      height.outer = number(h, "outer", 0.0);
      if (!lane.heights.empty() && height.s_offset < lane.heights.back().s_offset) {
        fail(h, "sOffset goes backwards");
      }
      lane.heights.push_back(height);
    }
    for (const pugi::xml_node m : node.children("roadMark")) {
      count_record(m);
      RoadMark mark;
      mark.s_offset = non_negative(m, "sOffset", 0.0);
      mark.type = m.attribute("type").as_string("none");
      mark.colour = m.attribute("color").as_string("standard");
      mark.width = non_negative(m, "width", 0.12);
      if (mark.width > 5.0) fail(m, "a road mark wider than 5 m");
      lane.marks.push_back(std::move(mark));
    }
    return lane;
  }

  // A side's lanes, sorted outwards; their ids must run 1, 2, ... (or -1, -2, ...) without gaps.
  std::vector<Lane> parse_side(const pugi::xml_node& side, int sign) {
    std::vector<Lane> lanes;
    if (!side) return lanes;
    for (const pugi::xml_node n : side.children("lane")) {
      if (lanes.size() >= limits_.max_lanes_per_side) {
        fail(n, "more than " + std::to_string(limits_.max_lanes_per_side) + " lanes on a side");
      }
      lanes.push_back(parse_lane(n));
      if (lanes.back().id * sign <= 0) {
        fail(n, "lane id " + std::to_string(lanes.back().id) + " on the " +
                    (sign > 0 ? "left (ids > 0)" : "right (ids < 0)"));
      }
    }
    std::sort(lanes.begin(), lanes.end(),
              [](const Lane& a, const Lane& b) { return std::abs(a.id) < std::abs(b.id); });
    for (std::size_t i = 0; i < lanes.size(); ++i) {
      if (std::abs(lanes[i].id) != static_cast<int>(i) + 1) {
        fail(side, "lane ids do not run 1, 2, ... outwards from the centre");
      }
    }
    return lanes;
  }

  Road parse_road(const pugi::xml_node& node) {
    count_record(node);
    Road road;
    road.id = node.attribute("id").as_string();
    if (road.id.empty()) fail(node, "attribute id is missing");
    road.name = node.attribute("name").as_string();
    road.junction = node.attribute("junction").as_string("-1");
    road.length = non_negative(node, "length");
    if (road.length <= 0.0 || road.length > limits_.max_road_length_m) {
      fail(node, "length " + std::to_string(road.length) + " is not in (0, " +
                     std::to_string(limits_.max_road_length_m) + "] m");
    }
    total_length_ += road.length;
    if (total_length_ > limits_.max_total_length_m) {
      fail(node, "the roads' lengths add up to more than " +
                     std::to_string(limits_.max_total_length_m) + " m");
    }
    if (const pugi::xml_node l = node.child("link")) {
      road.predecessor = link(l.child("predecessor"));
      road.successor = link(l.child("successor"));
    }
    const pugi::xml_node plan = node.child("planView");
    if (!plan) fail(node, "no <planView>");
    for (const pugi::xml_node g : plan.children("geometry")) parse_geometry(g, road);
    if (road.plan_view.empty()) fail(plan, "no <geometry>");
    if (const pugi::xml_node e = node.child("elevationProfile")) {
      road.elevation = cubics(e, "elevation", "s");
    }
    if (const pugi::xml_node l = node.child("lateralProfile")) {
      road.superelevation = cubics(l, "superelevation", "s");
    }
    const pugi::xml_node lanes = node.child("lanes");
    if (!lanes) fail(node, "no <lanes>");
    road.lane_offsets = cubics(lanes, "laneOffset", "s");
    for (const pugi::xml_node sec : lanes.children("laneSection")) {
      count_record(sec);
      LaneSection section;
      section.s = non_negative(sec, "s");
      if (!road.sections.empty() && section.s < road.sections.back().s) {
        fail(sec, "s goes backwards");
      }
      section.left = parse_side(sec.child("left"), 1);
      section.right = parse_side(sec.child("right"), -1);
      if (const pugi::xml_node c = sec.child("center")) {
        if (const pugi::xml_node lane = c.child("lane")) section.centre = parse_lane(lane);
      }
      road.sections.push_back(std::move(section));
    }
    if (road.sections.empty()) fail(lanes, "no <laneSection>");
    return road;
  }

  Junction parse_junction(const pugi::xml_node& node, const std::set<std::string>& roads) {
    count_record(node);
    Junction j;
    j.id = node.attribute("id").as_string();
    if (j.id.empty()) fail(node, "attribute id is missing");
    j.name = node.attribute("name").as_string();
    for (const pugi::xml_node c : node.children("connection")) {
      count_record(c);
      JunctionConnection conn;
      conn.id = c.attribute("id").as_string();
      conn.incoming_road = c.attribute("incomingRoad").as_string();
      conn.connecting_road = c.attribute("connectingRoad").as_string();
      for (const std::string* id : {&conn.incoming_road, &conn.connecting_road}) {
        if (!roads.count(*id)) fail(c, "road \"" + *id + "\" is not in the file");
      }
      conn.contact_end = std::string_view(c.attribute("contactPoint").as_string()) == "end";
      for (const pugi::xml_node l : c.children("laneLink")) {
        count_record(l);
        conn.lane_links.emplace_back(integer(l, "from"), integer(l, "to"));
      }
      j.connections.push_back(std::move(conn));
    }
    return j;
  }

  std::string_view text_;
  Limits limits_;
  std::size_t records_ = 0;
  std::size_t knots_ = 0;
  double total_length_ = 0.0;
};

}  // namespace

Network parse_opendrive(std::string_view xml, const Limits& limits) {
  return Parser(xml, limits).parse();
}

}  // namespace downpour::road