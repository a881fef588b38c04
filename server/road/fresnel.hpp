// The Fresnel integrals C(x) = integral from 0 to x of cos(pi t^2 / 2) dt and S(x) likewise of
// the sine: the clothoid's coordinates (a spiral whose curvature grows linearly with its length).
#pragma once

namespace downpour::road {

struct Fresnel {
  double c = 0.0;
  double s = 0.0;
};

// Both integrals at x (odd in x): the power series in long double up to |x| = 4 (its terms grow
// to some 1e10 before they cancel: about 1e-10 with x86-64's 80-bit long double, worse where long
// double is a double), the asymptotic expansion, cut at its smallest term, beyond.
Fresnel fresnel(double x);

// A point of the clothoid that starts at the origin heading along +x with curvature 0 and whose
// curvature grows by `rate` (1/m^2, either sign) per metre: at arc length s, its position and
// heading (rate s^2 / 2).
struct ClothoidPoint {
  double x = 0.0;
  double y = 0.0;
  double heading = 0.0;
};
ClothoidPoint standard_clothoid(double rate, double s);

}  // namespace downpour::road
