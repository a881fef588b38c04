#include "server/sim/track_opendrive.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace downpour::sim {
namespace {

constexpr double kCrestPiece_m = 10.0;

// A number as the file holds it: enough digits for micrometres over a 100 km road.
std::string num(double v) {
  char text[40];
  std::snprintf(text, sizeof text, "%.12g", std::abs(v) < 1e-12 ? 0.0 : v);
  return text;
}

std::string cubic(const char* tag, double s, double a, double b, double c, double d) {
  return std::string("      <") + tag + " s=\"" + num(s) + "\" a=\"" + num(a) + "\" b=\"" + num(b) +
         "\" c=\"" + num(c) + "\" d=\"" + num(d) + "\"/>\n";
}

// One lane of the track: its width, its surface's fall from the crown at its inner and outer
// border, and the mark on its outer border.
std::string lane(int id, const char* type, double width, double inner_z, double outer_z,
                 const char* mark, double mark_width) {
  std::string out =
      "        <lane id=\"" + std::to_string(id) + "\" type=\"" + type + "\" level=\"false\">\n";
  out += "          <width sOffset=\"0\" a=\"" + num(width) + "\" b=\"0\" c=\"0\" d=\"0\"/>\n";
  out += "          <height sOffset=\"0\" inner=\"" + num(inner_z) + "\" outer=\"" + num(outer_z) +
         "\"/>\n";
  if (mark) {
    out += std::string("          <roadMark sOffset=\"0\" type=\"") + mark +
           "\" color=\"white\" width=\"" + num(mark_width) + "\"/>\n";
  }
  out += "        </lane>\n";
  return out;
}

}  // namespace

std::string track_to_opendrive(const Track& track) {
  std::string x = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<OpenDRIVE>\n";
  x += "  <header revMajor=\"1\" revMinor=\"6\" name=\"Downpour test track\" "
       "vendor=\"Downpour\"/>\n";
  x += "  <road name=\"test track\" length=\"" + num(track.length()) +
       "\" id=\"1\" junction=\"-1\">\n";
  x += R"(    <link>
      <predecessor elementType="road" elementId="1" contactPoint="end"/>
      <successor elementType="road" elementId="1" contactPoint="start"/>
    </link>
    <type s="0" type="motorway"/>
    <planView>
)";
  for (const Track::Segment& seg : track.segments()) {
    x += "      <geometry s=\"" + num(seg.s0) + "\" x=\"" + num(seg.start.x) + "\" y=\"" +
         num(seg.start.y) + "\" hdg=\"" + num(seg.heading0) + "\" length=\"" + num(seg.length) +
         "\">";
    x += seg.curvature == 0.0 ? "<line/>" : "<arc curvature=\"" + num(seg.curvature) + "\"/>";
    x += "</geometry>\n";
  }
  x += "    </planView>\n";
  // Flat but for the hills, each as Hermite cubics through the track's own heights and grades.
  x += "    <elevationProfile>\n";
  x += cubic("elevation", 0.0, 0.0, 0.0, 0.0, 0.0);
  for (const Track::Crest& crest : track.crests()) {
    const double s0 = crest.s_centre - crest.half_length, s1 = crest.s_centre + crest.half_length;
    const int pieces = static_cast<int>(std::ceil((s1 - s0) / kCrestPiece_m));
    for (int i = 0; i < pieces; ++i) {
      const double a = s0 + (s1 - s0) * i / pieces, b = s0 + (s1 - s0) * (i + 1) / pieces;
      const double h = b - a;
      const TrackFrame fa = track.at(a), fb = track.at(b);
      const double z0 = fa.position.z, z1 = fb.position.z, g0 = fa.grade, g1 = fb.grade;
      const double dz = (z1 - z0) / h;
      x += cubic("elevation", a, z0, g0, (3.0 * dz - 2.0 * g0 - g1) / h,
                 (g0 + g1 - 2.0 * dz) / (h * h));
    }
    x += cubic("elevation", s1, 0.0, 0.0, 0.0, 0.0);
  }
  x += "    </elevationProfile>\n";
  x += "    <lateralProfile/>\n";
  // The cross-section: lanes out from the centreline, each side the same; the crown's fall as
  // each lane's height; the markings as the render draws them (a double centre line, dashed
  // lane dividers, solid edge lines).
  const CrossSection& c = track.cross_section();
  // Each side's lanes by id, from the top down as the standard lists them: the left's from the
  // outermost in, the right's from the innermost out (SUMO's netconvert reads them in that order).
  const auto side = [&](int sign) {
    std::vector<std::string> lanes_out;
    const int lanes = c.lanes_each_way;
    for (int i = 1; i <= lanes; ++i) {
      const double inner = (i - 1) * c.lane_width_m, outer = i * c.lane_width_m;
      lanes_out.push_back(lane(sign * i, "driving", c.lane_width_m, -c.crown_slope * inner,
                               -c.crown_slope * outer, i < lanes ? "broken" : "solid",
                               i < lanes ? 0.15 : 0.2));
    }
    const double edge = lanes * c.lane_width_m;
    lanes_out.push_back(lane(sign * (lanes + 1), "shoulder", c.shoulder_m, -c.crown_slope * edge,
                             -c.crown_slope * (edge + c.shoulder_m), nullptr, 0.0));
    if (sign > 0) std::reverse(lanes_out.begin(), lanes_out.end());
    std::string out;
    for (const std::string& l : lanes_out) out += l;
    return out;
  };
  x += "    <lanes>\n";
  x += "      <laneSection s=\"0\">\n      <left>\n" + side(1) + R"(      </left>
      <center>
        <lane id="0" type="none" level="false">
          <roadMark sOffset="0" type="solid solid" color="white" width="0.14"/>
        </lane>
      </center>
      <right>
)" + side(-1) +
       "      </right>\n";
  x += "      </laneSection>\n";
  x += "    </lanes>\n";
  x += "  </road>\n</OpenDRIVE>\n";
  return x;
}

}  // namespace downpour::sim
