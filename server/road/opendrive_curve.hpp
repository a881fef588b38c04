// What the road model's evaluation (opendrive.cpp) and the OpenDRIVE parser (opendrive_parse.cpp)
// share of the poly3 / paramPoly3 curves: the quadrature, the local curve and the parameter at an
// arc length (the parser builds the arc length tables that the model evaluates through).
#pragma once

#include <array>
#include <cmath>

#include "server/road/opendrive.hpp"

namespace downpour::road {

// The integral of f over [a, b] by 5-point Gauss-Legendre (exact for degree 9; the curves'
// speeds are smooth).
template <typename F>
double gauss5(F&& f, double a, double b) {
  static constexpr std::array<double, 5> kX{0.0, 0.5384693101056831, -0.5384693101056831,
                                            0.9061798459386640, -0.9061798459386640};
  static constexpr std::array<double, 5> kW{0.5688888888888889, 0.4786286704993665,
                                            0.4786286704993665, 0.2369268850561891,
                                            0.2369268850561891};
  const double mid = 0.5 * (a + b), half = 0.5 * (b - a);
  double sum = 0.0;
  for (int i = 0; i < 5; ++i) sum += kW[i] * f(mid + half * kX[i]);
  return sum * half;
}

// The local curve of a poly3 or paramPoly3 record: (u(p), v(p)) and its derivative.
struct LocalCurve {
  const Geometry& g;
  double u(double p) const { return g.au + p * (g.bu + p * (g.cu + p * g.du)); }
  double v(double p) const { return g.av + p * (g.bv + p * (g.cv + p * g.dv)); }
  double du(double p) const { return g.bu + p * (2.0 * g.cu + p * 3.0 * g.du); }
  double dv(double p) const { return g.bv + p * (2.0 * g.cv + p * 3.0 * g.dv); }
  double speed(double p) const { return std::hypot(du(p), dv(p)); }
  double arc(double p0, double p1) const {
    return gauss5([this](double p) { return speed(p); }, p0, p1);
  }
};

// The parameter of a poly3 / paramPoly3 record at arc length ds: the knot interval by search,
// then Newton's steps on the arc length within it.
double param_at(const Geometry& g, double ds);

}  // namespace downpour::road
