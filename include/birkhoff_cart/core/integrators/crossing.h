// Where a function of time crosses zero inside a bracket: the Illinois variant of regula falsi,
// safeguarded by bisection, for locating events on a dense output (the Python module's solve(),
// docs/python.md "Events"). Header-only, ROS-free, no cart code.
#pragma once

#include <cmath>
#include <cstdint>

namespace birkhoff_cart {

/// A located crossing: the time [s] and how it was found.
struct Crossing {
  double time = 0.0;             ///< the estimate of the root [s]: the bracket end where g is smaller in size
  double bracket_width = 0.0;    ///< width of the final bracket [s]: the root lies in it (g continuous)
  std::uint32_t evaluations = 0;  ///< calls of g
};

/// The root of g in [a, b] (a < b [s]), given g(a) = ga and g(b) = gb of opposite signs or one of them
/// zero. Illinois steps (the retained end's value halved when it is kept twice), and a bisection
/// whenever a step fails to halve the bracket, so the bracket shrinks at least by half every two
/// evaluations; stops when it is no wider than `time_tolerance` [s] (or an ulp of its ends), when g
/// is exactly zero, or after `max_evaluations`.
template <class Function>
Crossing locate_crossing(Function&& g, double a, double ga, double b, double gb, double time_tolerance,
                         std::uint32_t max_evaluations = 200) {
  Crossing result;
  if (ga == 0.0) {
    result.time = a;
    return result;
  }
  if (gb == 0.0) {
    result.time = b;
    return result;
  }
  int kept = 0;  // +1: b kept by the last step, −1: a kept, 0: a bisection
  // Evaluates g at c (a < c < b) and keeps the half of the bracket where g changes sign; with
  // `illinois`, halves the value of an end kept twice running. True when g(c) is exactly zero.
  const auto narrow = [&](double c, bool illinois) {
    const double gc = g(c);
    ++result.evaluations;
    if (gc == 0.0) {
      result.time = c;
      return true;
    }
    const int keep = (gc < 0.0) == (ga < 0.0) ? 1 : -1;
    (keep == 1 ? a : b) = c;
    (keep == 1 ? ga : gb) = gc;
    if (illinois && keep == kept) (keep == 1 ? gb : ga) *= 0.5;
    kept = illinois ? keep : 0;
    return false;
  };
  while (b - a > time_tolerance && result.evaluations < max_evaluations) {
    const double width = b - a;
    double c = b - gb * (b - a) / (gb - ga);  // regula falsi
    if (!(c > a && c < b)) c = 0.5 * (a + b);
    if (!(c > a && c < b)) break;  // no double between a and b
    if (narrow(c, true)) return result;
    if (b - a > 0.5 * width && b - a > time_tolerance) {  // a poor step: bisect once
      const double m = 0.5 * (a + b);
      if (!(m > a && m < b)) break;
      if (narrow(m, false)) return result;
    }
  }
  result.time = std::abs(ga) <= std::abs(gb) ? a : b;
  result.bracket_width = b - a;
  return result;
}

}  // namespace birkhoff_cart
