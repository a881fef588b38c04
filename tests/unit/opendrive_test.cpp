// OpenDRIVE roads: each plan-view geometry against closed forms or an independent quadrature,
// lanes and profiles of a hand-written file, and files refused with the element and line named.
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

#include <gtest/gtest.h>

#include "server/road/fresnel.hpp"
#include "server/road/opendrive.hpp"

namespace downpour::road {
namespace {

constexpr double kPi = std::numbers::pi;

// The end of a curve whose heading is h0 + k0 u + rate u^2 / 2, from (0, 0), by Simpson's rule in
// long double: independent of the Fresnel integrals.
RefPoint quadrature(double h0, double k0, double rate, double length) {
  const int n = 20000;
  const long double h = static_cast<long double>(length) / n;
  long double x = 0.0L, y = 0.0L;
  for (int i = 0; i <= n; ++i) {
    const long double u = i * h;
    const long double w = (i == 0 || i == n) ? 1.0L : (i % 2 ? 4.0L : 2.0L);
    const long double a = h0 + k0 * u + 0.5L * rate * u * u;
    x += w * std::cos(a);
    y += w * std::sin(a);
  }
  return {static_cast<double>(x * h / 3.0L), static_cast<double>(y * h / 3.0L),
          h0 + k0 * length + 0.5 * rate * length * length};
}

TEST(Fresnel, MatchesTabulatedValuesAndQuadrature) {
  // Tabulated (Abramowitz and Stegun, table 7.7).
  EXPECT_NEAR(fresnel(1.0).c, 0.7798934003768228, 1e-12);
  EXPECT_NEAR(fresnel(1.0).s, 0.4382591473903548, 1e-12);
  EXPECT_NEAR(fresnel(2.0).c, 0.4882534060753408, 1e-11);
  EXPECT_NEAR(fresnel(2.0).s, 0.3434156783636982, 1e-11);
  EXPECT_NEAR(fresnel(-1.0).c, -0.7798934003768228, 1e-12);  // odd
  // Either side of the switch from the series to the asymptotic expansion, and far out.
  for (const double x : {3.9, 4.1, 6.0, 9.5}) {
    const RefPoint q = quadrature(0.0, 0.0, kPi, x);  // heading pi u^2 / 2
    EXPECT_NEAR(fresnel(x).c, q.x, 1e-9) << x;
    EXPECT_NEAR(fresnel(x).s, q.y, 1e-9) << x;
  }
}

Geometry record(Geometry::Kind kind, double x, double y, double heading, double length) {
  Geometry g;
  g.kind = kind;
  g.x = x, g.y = y, g.heading = heading, g.length = length;
  return g;
}

TEST(OpenDriveGeometry, ClothoidEndPointsAreTheClosedForm) {
  // A spiral from straight to curvature pi / 100 over 100 m: its parameter a = 100 / sqrt(pi),
  // so its end is 100 (C(1), S(1)) in the record's frame, heading pi / 2.
  Geometry g = record(Geometry::Kind::kSpiral, 0.0, 0.0, 0.0, 100.0);
  g.curv_start = 0.0;
  g.curv_end = kPi / 100.0;
  RefPoint end = g.at(100.0);
  EXPECT_NEAR(end.x, 77.98934003768228, 1e-6);
  EXPECT_NEAR(end.y, 43.82591473903548, 1e-6);
  EXPECT_NEAR(end.heading, kPi / 2.0, 1e-12);
  // The same record placed at (10, -5) heading 30 degrees: the end rotates and moves with it.
  g.x = 10.0, g.y = -5.0, g.heading = kPi / 6.0;
  end = g.at(100.0);
  const double c = std::cos(kPi / 6.0), s = std::sin(kPi / 6.0);
  EXPECT_NEAR(end.x, 10.0 + c * 77.98934003768228 - s * 43.82591473903548, 1e-6);
  EXPECT_NEAR(end.y, -5.0 + s * 77.98934003768228 + c * 43.82591473903548, 1e-6);
  // Turning right: mirrored.
  g = record(Geometry::Kind::kSpiral, 0.0, 0.0, 0.0, 100.0);
  g.curv_end = -kPi / 100.0;
  EXPECT_NEAR(g.at(100.0).y, -43.82591473903548, 1e-6);
}

TEST(OpenDriveGeometry, SpiralsBetweenCurvaturesMatchQuadrature) {
  struct Case {
    double k0, k1, length;
  };
  // From one curvature to another, through zero (an S-bend), easing out, and a rate so small
  // that the Fresnel form gives way to quadrature.
  for (const Case& k : {Case{0.01, 0.02, 50.0}, Case{0.02, -0.01, 80.0}, Case{-0.004, 0.0, 120.0},
                        Case{0.01, 0.01 + 1e-9, 200.0}}) {
    Geometry g = record(Geometry::Kind::kSpiral, 3.0, 4.0, 0.7, k.length);
    g.curv_start = k.k0;
    g.curv_end = k.k1;
    const double rate = (k.k1 - k.k0) / k.length;
    for (const double ds : {k.length * 0.37, k.length}) {
      const RefPoint q = quadrature(0.7, k.k0, rate, ds);
      const RefPoint p = g.at(ds);
      EXPECT_NEAR(p.x, 3.0 + q.x, 1e-6) << k.k0 << " -> " << k.k1 << " at " << ds;
      EXPECT_NEAR(p.y, 4.0 + q.y, 1e-6) << k.k0 << " -> " << k.k1 << " at " << ds;
      EXPECT_NEAR(p.heading, q.heading, 1e-12);
    }
  }
}

TEST(OpenDriveGeometry, LinesAndArcs) {
  const Geometry line = record(Geometry::Kind::kLine, 1.0, 2.0, kPi / 4.0, 10.0);
  EXPECT_NEAR(line.at(10.0).x, 1.0 + 10.0 / std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(line.at(10.0).y, 2.0 + 10.0 / std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(line.at(25.0).x, line.at(10.0).x, 1e-12) << "clamped to the record";
  // A quarter circle of radius 100 turning left, then one turning right.
  Geometry arc = record(Geometry::Kind::kArc, 0.0, 0.0, 0.0, 50.0 * kPi);
  arc.curvature = 0.01;
  EXPECT_NEAR(arc.at(50.0 * kPi).x, 100.0, 1e-9);
  EXPECT_NEAR(arc.at(50.0 * kPi).y, 100.0, 1e-9);
  EXPECT_NEAR(arc.at(50.0 * kPi).heading, kPi / 2.0, 1e-12);
  arc.curvature = -0.01;
  EXPECT_NEAR(arc.at(50.0 * kPi).y, -100.0, 1e-9);
}

// The parabola v = 0.002 u^2: its arc length from u = 0 (the integral of sqrt(1 + (0.004 u)^2),
// closed form), and the u where that reaches `arc` (by bisection).
double arc_to(double u) {
  const double w = 0.004 * u;
  return (w * std::sqrt(1.0 + w * w) + std::asinh(w)) / (2.0 * 0.004);
}
double parabola_u_at(double arc) {
  double lo = 0.0, hi = arc;
  for (int i = 0; i < 80; ++i) (arc_to(0.5 * (lo + hi)) < arc ? lo : hi) = 0.5 * (lo + hi);
  return 0.5 * (lo + hi);
}

TEST(OpenDriveGeometry, CubicCurvesFollowTheirArcLength) {
  // poly3 v = 0.002 u^2 over 80 m of arc, and the same curve as a paramPoly3 in both parameter
  // ranges: the same points at the same arc lengths.
  Geometry poly = record(Geometry::Kind::kPoly3, 0.0, 0.0, 0.0, 80.0);
  poly.bu = 1.0;
  poly.cv = 0.002;
  const auto knots = [](Geometry& g, double p_end) {
    // As the parser builds them (the arc length at equal steps of the parameter).
    const int n = 400;
    g.p_end = p_end;
    g.knot_s.assign(n + 1, 0.0);
    for (int k = 0; k < n; ++k) {
      double arc = 0.0;
      for (int j = 0; j < 50; ++j) {
        const double p = p_end * (k + (j + 0.5) / 50.0) / n;
        const double du = g.bu + p * (2.0 * g.cu + 3.0 * p * g.du);
        const double dv = g.bv + p * (2.0 * g.cv + 3.0 * p * g.dv);
        arc += std::hypot(du, dv) * p_end / n / 50.0;
      }
      g.knot_s[k + 1] = g.knot_s[k] + arc;
    }
  };
  const double u_end = parabola_u_at(80.0);
  knots(poly, u_end);
  const RefPoint end = poly.at(80.0);
  EXPECT_NEAR(end.x, u_end, 1e-6);
  EXPECT_NEAR(end.y, 0.002 * u_end * u_end, 1e-6);
  EXPECT_NEAR(end.heading, std::atan(0.004 * u_end), 1e-9);
  const RefPoint mid = poly.at(40.0);
  EXPECT_NEAR(arc_to(mid.x), 40.0, 1e-6) << "the point 40 m along is 40 m of arc along";

  Geometry normalized = record(Geometry::Kind::kParamPoly3, 0.0, 0.0, 0.0, 80.0);
  normalized.bu = u_end;                  // u = u_end p
  normalized.cv = 0.002 * u_end * u_end;  // v = 0.002 u^2
  knots(normalized, 1.0);
  Geometry arc_length = record(Geometry::Kind::kParamPoly3, 0.0, 0.0, 0.0, 80.0);
  arc_length.p_normalized = false;
  arc_length.bu = u_end / 80.0;
  arc_length.cv = 0.002 * (u_end / 80.0) * (u_end / 80.0);
  knots(arc_length, 80.0);
  for (const double ds : {0.0, 13.0, 40.0, 80.0}) {
    EXPECT_NEAR(normalized.at(ds).x, poly.at(ds).x, 1e-6) << ds;
    EXPECT_NEAR(normalized.at(ds).y, poly.at(ds).y, 1e-6) << ds;
    EXPECT_NEAR(arc_length.at(ds).x, poly.at(ds).x, 1e-6) << ds;
    EXPECT_NEAR(arc_length.at(ds).y, poly.at(ds).y, 1e-6) << ds;
  }
}

TEST(OpenDrive, ParsedCubicCurvesReachTheirLength) {
  // v = 0.002 u^2 as a poly3 and as a paramPoly3 over its arc length, read from a file: the
  // parser's own arc-length tables put the 80 m point where the closed form does.
  const double u_end = parabola_u_at(80.0);
  const double k = u_end / 80.0;
  const auto exact = [](double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%.17g", v);
    return std::string(text);
  };
  const std::string file = R"(<OpenDRIVE><road id="p" length="160"><planView>
      <geometry s="0" x="0" y="0" hdg="0" length="80"><poly3 a="0" b="0" c="0.002" d="0"/></geometry>
      <geometry s="80" x="0" y="0" hdg="0" length="80">
        <paramPoly3 aU="0" bU=")" +
                           exact(k) + R"(" cU="0" dU="0" aV="0" bV="0" cV=")" +
                           exact(0.002 * k * k) + R"(" dV="0" pRange="arcLength"/>
      </geometry></planView>
      <lanes><laneSection s="0"><right><lane id="-1"><width sOffset="0" a="3" b="0" c="0" d="0"/>
      </lane></right></laneSection></lanes></road></OpenDRIVE>)";
  const Network net = parse_opendrive(file);
  const Road& road = net.roads.at(0);
  for (const double s : {80.0 - 1e-9, 160.0}) {
    EXPECT_NEAR(road.reference(s).x, u_end, 1e-5) << s;
    EXPECT_NEAR(road.reference(s).y, 0.002 * u_end * u_end, 1e-5) << s;
  }
  EXPECT_NEAR(arc_to(road.reference(30.0).x), 30.0, 1e-6);
  EXPECT_NEAR(arc_to(road.reference(110.0).x), 30.0, 1e-4);
  // The curves' samples count against a limit.
  Limits few;
  few.max_curve_knots = 300;
  try {
    parse_opendrive(file, few);
    ADD_FAILURE() << "parsed";
  } catch (const ParseError& e) {
    EXPECT_NE(std::string(e.what()).find("samples"), std::string::npos) << e.what();
  }
}

// A two-road file with a junction: a straight, then a spiral and arc into a bend, lanes with
// changing widths, a lane offset, a crest, superelevation and road marks.
const char* kTwoRoads = R"(<?xml version="1.0" standalone="yes"?>
<OpenDRIVE>
  <header revMajor="1" revMinor="6" name="two roads"/>
  <road name="straight" length="100.0" id="1" junction="-1">
    <link><successor elementType="junction" elementId="9"/></link>
    <planView>
      <geometry s="0.0" x="0.0" y="0.0" hdg="0.0" length="100.0"><line/></geometry>
    </planView>
    <elevationProfile>
      <elevation s="0.0" a="10.0" b="0.02" c="0.0" d="0.0"/>
    </elevationProfile>
    <lateralProfile>
      <superelevation s="0.0" a="0.03" b="0.0" c="0.0" d="0.0"/>
    </lateralProfile>
    <lanes>
      <laneOffset s="0.0" a="0.5" b="0.0" c="0.0" d="0.0"/>
      <laneSection s="0.0">
        <left>
          <lane id="2" type="shoulder" level="false"><width sOffset="0.0" a="1.5" b="0" c="0" d="0"/></lane>
          <lane id="1" type="driving" level="false">
            <width sOffset="0.0" a="3.5" b="0" c="0" d="0"/>
            <roadMark sOffset="0.0" type="broken" color="white" width="0.15"/>
          </lane>
        </left>
        <center><lane id="0" type="none"><roadMark sOffset="0" type="solid solid" color="yellow" width="0.12"/></lane></center>
        <right>
          <lane id="-1" type="driving"><width sOffset="0.0" a="3.5" b="0.0" c="0.0" d="0.0"/></lane>
        </right>
      </laneSection>
      <laneSection s="50.0">
        <right>
          <lane id="-1" type="driving"><width sOffset="0.0" a="3.5" b="0.01" c="0" d="0"/></lane>
          <lane id="-2" type="shoulder"><width sOffset="0.0" a="2.0" b="0" c="0" d="0"/></lane>
        </right>
      </laneSection>
    </lanes>
  </road>
  <road name="bend" length="80.0" id="2" junction="9">
    <planView>
      <geometry s="0.0" x="100.0" y="0.0" hdg="0.0" length="40.0"><spiral curvStart="0.0" curvEnd="0.02"/></geometry>
      <geometry s="40.0" x="139.365" y="5.273" hdg="0.4" length="40.0"><arc curvature="0.02"/></geometry>
    </planView>
    <lanes>
      <laneSection s="0.0">
        <right><lane id="-1" type="driving"><width sOffset="0.0" a="3.5" b="0" c="0" d="0"/></lane></right>
      </laneSection>
    </lanes>
  </road>
  <junction id="9" name="end">
    <connection id="0" incomingRoad="1" connectingRoad="2" contactPoint="start">
      <laneLink from="-1" to="-1"/>
    </connection>
  </junction>
</OpenDRIVE>
)";

TEST(OpenDrive, ReadsRoadsLanesProfilesAndJunctions) {
  const Network net = parse_opendrive(kTwoRoads);
  EXPECT_EQ(net.name, "two roads");
  EXPECT_EQ(net.rev_minor, 6);
  ASSERT_EQ(net.roads.size(), 2u);
  const Road& straight = *net.find_road("1");
  EXPECT_EQ(straight.successor.type, RoadLink::Type::kJunction);
  EXPECT_EQ(straight.successor.id, "9");
  // Elevation and superelevation: 10 m + 2%, the left side 3% of roll higher.
  EXPECT_NEAR(straight.height(50.0), 11.0, 1e-12);
  EXPECT_NEAR(straight.surface_height(50.0, 2.0), 11.0 + 2.0 * std::tan(0.03), 1e-12);
  // Lanes: the centre lane 0.5 m left of the reference line; left 1 (3.5 m) then the shoulder.
  EXPECT_NEAR(straight.lane_border(10.0, 0), 0.5, 1e-12);
  EXPECT_NEAR(straight.lane_border(10.0, 1), 4.0, 1e-12);
  EXPECT_NEAR(straight.lane_border(10.0, 2), 5.5, 1e-12);
  EXPECT_NEAR(straight.lane_border(10.0, -1), -3.0, 1e-12);
  // The second section: the right lane widens by 1 cm a metre from s = 50 on; no left lanes.
  EXPECT_NEAR(straight.lane_border(70.0, -1), 0.5 - 3.7, 1e-12);
  EXPECT_NEAR(straight.lane_border(70.0, -2), 0.5 - 5.7, 1e-12);
  EXPECT_NEAR(straight.lane_border(70.0, 1), 0.5, 1e-12);
  const LaneSection& first = straight.section_at(0.0);
  ASSERT_EQ(first.left.size(), 2u);
  EXPECT_EQ(first.left[0].id, 1) << "sorted outwards";
  ASSERT_EQ(first.left[0].marks.size(), 1u);
  EXPECT_EQ(first.left[0].marks[0].type, "broken");
  EXPECT_EQ(first.centre.marks[0].colour, "yellow");
  EXPECT_DOUBLE_EQ(first.left[0].marks[0].width, 0.15);

  const Road& bend = *net.find_road("2");
  EXPECT_EQ(bend.junction, "9");
  // The spiral's end, by quadrature, is where the file puts the arc's start (to its 1 cm).
  const RefPoint q = quadrature(0.0, 0.0, 0.02 / 40.0, 40.0);
  EXPECT_NEAR(bend.reference(40.0 - 1e-9).x, 100.0 + q.x, 1e-6);
  EXPECT_NEAR(bend.reference(40.0 - 1e-9).y, q.y, 1e-6);
  EXPECT_NEAR(bend.reference(40.0).x, 139.365, 0.01);
  EXPECT_NEAR(bend.reference(40.0).y, 5.273, 0.01);
  ASSERT_EQ(net.junctions.size(), 1u);
  ASSERT_EQ(net.junctions[0].connections.size(), 1u);
  EXPECT_EQ(net.junctions[0].connections[0].connecting_road, "2");
  EXPECT_EQ(net.junctions[0].connections[0].lane_links[0], std::make_pair(-1, -1));
}

// The file with one piece of text replaced (which must be there).
std::string with(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

// The error parsing `text` raises (failing the test if none).
ParseError refused(const std::string& text, const Limits& limits = {}) {
  try {
    parse_opendrive(text, limits);
  } catch (const ParseError& e) {
    return e;
  }
  ADD_FAILURE() << "parsed";
  return ParseError("", 0, "");
}

TEST(OpenDrive, RefusesBadFilesNamingTheElementAndLine) {
  ParseError e =
      refused(with(kTwoRoads, R"(hdg="0.0" length="100.0")", R"(hdg="east" length="100.0")"));
  EXPECT_EQ(e.element(), "geometry");
  EXPECT_EQ(e.line(), 7);
  EXPECT_NE(std::string(e.what()).find("hdg=\"east\""), std::string::npos) << e.what();

  e = refused(with(kTwoRoads, R"(<arc curvature="0.02"/>)", R"(<arc curvature="nan"/>)"));
  EXPECT_EQ(e.element(), "arc");
  EXPECT_EQ(e.line(), 41);

  e = refused(
      with(kTwoRoads, R"(<lane id="2" type="shoulder")", R"(<lane id="3" type="shoulder")"));
  EXPECT_EQ(e.element(), "left") << e.what();

  e = refused(with(kTwoRoads, R"(<line/>)", ""));
  EXPECT_EQ(e.element(), "geometry");
  EXPECT_NE(std::string(e.what()).find("exactly one"), std::string::npos);

  e = refused(with(kTwoRoads, R"(connectingRoad="2")", R"(connectingRoad="7")"));
  EXPECT_EQ(e.element(), "connection");

  e = refused(with(kTwoRoads, R"(<road name="bend" length="80.0" id="2")",
                   R"(<road name="bend" length="80.0" id="1")"));
  EXPECT_EQ(e.element(), "road");
  EXPECT_EQ(e.line(), 38);

  e = refused(with(kTwoRoads, "</planView>\n    <lanes>", "</planView>\n    <lanes"));
  EXPECT_EQ(e.element(), "OpenDRIVE");
  EXPECT_GT(e.line(), 0);
  EXPECT_NE(std::string(e.what()).find("XML"), std::string::npos) << e.what();

  e = refused("<road/>");
  EXPECT_NE(std::string(e.what()).find("no <OpenDRIVE>"), std::string::npos);
}

TEST(OpenDrive, LimitsBoundWhatAFileMayCost) {
  Limits limits;
  limits.max_bytes = 1000;
  EXPECT_NE(std::string(refused(kTwoRoads, limits).what()).find("bytes"), std::string::npos);
  limits = {};
  limits.max_roads = 1;
  EXPECT_EQ(refused(kTwoRoads, limits).element(), "road");
  limits = {};
  limits.max_records = 10;
  EXPECT_NE(std::string(refused(kTwoRoads, limits).what()).find("records"), std::string::npos);
  limits = {};
  limits.max_lanes_per_side = 1;
  EXPECT_EQ(refused(kTwoRoads, limits).element(), "lane");
  EXPECT_EQ(
      refused(with(kTwoRoads, R"(length="100.0" id="1")", R"(length="1e9" id="1")")).element(),
      "road");
  EXPECT_EQ(refused(with(kTwoRoads, R"(x="139.365")", R"(x="1e12")")).element(), "geometry");
  EXPECT_EQ(
      refused(with(kTwoRoads, R"(<arc curvature="0.02"/>)", R"(<arc curvature="2"/>)")).element(),
      "arc");
}

}  // namespace
}  // namespace downpour::road
