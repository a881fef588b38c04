#include "server/road/fresnel.hpp"

#include <cmath>
#include <numbers>

namespace downpour::road {

Fresnel fresnel(double x) {
  const double ax = std::abs(x);
  const double sign = x < 0.0 ? -1.0 : 1.0;
  constexpr double kPi = std::numbers::pi;
  if (ax <= 4.0) {
    // C = sum (-1)^n (pi/2)^(2n) x^(4n+1) / ((2n)! (4n+1)), S = sum (-1)^n (pi/2)^(2n+1)
    // x^(4n+3) / ((2n+1)! (4n+3)): one running term t_k = (pi x^2 / 2)^k / k! times x.
    // In long double: the terms grow to some 1e10 at x = 4 before they cancel.
    const long double z = 0.5L * std::numbers::pi_v<long double> * ax * ax;
    long double term = ax;  // z^k / k! * x, k = 0
    long double c = 0.0L, s = 0.0L;
    for (int k = 0; k < 120; ++k) {
      const long double contribution = term / (2.0L * k + 1.0L);
      // k even: cosine's series (sign (-1)^(k/2)); k odd: sine's (sign (-1)^((k-1)/2)).
      const long double signed_term = ((k / 2) % 2 == 0) ? contribution : -contribution;
      if (k % 2 == 0) {
        c += signed_term;
      } else {
        s += signed_term;
      }
      term *= z / (k + 1.0L);
      if (term < 1e-20L && k > 4) break;
    }
    return {sign * static_cast<double>(c), sign * static_cast<double>(s)};
  }
  // C = 1/2 + f sin(pi x^2 / 2) - g cos(...), S = 1/2 - f cos(...) - g sin(...), with the
  // asymptotic series f ~ 1/(pi x) sum (-1)^m (4m-1)!! / (pi x^2)^(2m) and
  // g ~ 1/(pi^2 x^3) sum (-1)^m (4m+1)!! / (pi x^2)^(2m); each cut where its terms stop falling.
  const double w = kPi * ax * ax;
  double f = 0.0, g = 0.0;
  {
    double term = 1.0, last = 2.0;
    for (int m = 0; m < 40 && std::abs(term) < last; ++m) {
      f += term;
      last = std::abs(term);
      // (4m+3)(4m+1) / w^2: the next double factorial's two factors.
      term *= -(4.0 * m + 1.0) * (4.0 * m + 3.0) / (w * w);
    }
    f /= kPi * ax;
  }
  {
    double term = 1.0, last = 2.0;
    for (int m = 0; m < 40 && std::abs(term) < last; ++m) {
      g += term;
      last = std::abs(term);
      term *= -(4.0 * m + 3.0) * (4.0 * m + 5.0) / (w * w);
    }
    g /= kPi * kPi * ax * ax * ax;
  }
  const double phase = 0.5 * w;
  const double sn = std::sin(phase), cs = std::cos(phase);
  return {sign * (0.5 + f * sn - g * cs), sign * (0.5 - f * cs - g * sn)};
}

ClothoidPoint standard_clothoid(double rate, double s) {
  if (rate == 0.0) return {s, 0.0, 0.0};
  // x + i y = a sqrt(pi) (C(t) + i S(t)), t = s / (a sqrt(pi)), a = 1 / sqrt(|rate|); a falling
  // curvature mirrors it.
  const double a = 1.0 / std::sqrt(std::abs(rate));
  const double scale = a * std::sqrt(std::numbers::pi);
  const Fresnel f = fresnel(s / scale);
  const double side = rate < 0.0 ? -1.0 : 1.0;
  return {scale * f.c, side * scale * f.s, 0.5 * rate * s * s};
}

}  // namespace downpour::road
