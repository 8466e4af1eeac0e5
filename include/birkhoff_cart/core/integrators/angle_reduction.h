// Angles kept as a reduced part and whole turns, or as a double-double (hi + lo), so that the ulp of
// an angle that has turned many times does not decide the accuracy of what is periodic in it
// (docs/birkhoffian.md §10.4).
#pragma once

#include <cmath>

namespace birkhoff_cart {

/// 2π = kTwoPiHigh + kTwoPiLow to about 1e-32 rad.
constexpr double kTwoPiHigh = 6.283185307179586;       // [rad]
constexpr double kTwoPiLow = 2.4492935982947064e-16;   // [rad]

/// Reduces `angle` [rad] (with its remainder [rad]) into (−π, π], adding the removed turns to `turns`.
inline void reduce_angle(double& angle, double& remainder, double& turns) {
  const double k = std::nearbyint(angle / kTwoPiHigh);
  if (k == 0.0) return;
  angle = std::fma(-k, kTwoPiHigh, angle);  // one rounding; the exact result is near a small number
  remainder -= k * kTwoPiLow;
  turns += k;
}

/// The angle hi + lo [rad] reduced to about (−π, π], as one double accurate to an ulp of the result
/// (not of hi): where a function that is 2π-periodic in the angle is evaluated.
inline double reduced_angle(double high, double low) {
  const double k = std::nearbyint(high / kTwoPiHigh);
  if (k == 0.0) return high + low;
  return std::fma(-k, kTwoPiHigh, high) + (low - k * kTwoPiLow);
}

/// hi + lo = reduced + remainder + turns·2π, hi the nearest double (an unwrapped angle that keeps the
/// bits the reduced form had in its low part).
inline void unwrap_angle(double reduced, double remainder, double turns, double& high, double& low) {
  const double product = turns * kTwoPiHigh;
  const double product_error = std::fma(turns, kTwoPiHigh, -product);  // exact: turns·2π_hi − product
  high = reduced + product;
  const double virtual_product = high - reduced;
  const double sum_error = (reduced - (high - virtual_product)) + (product - virtual_product);  // TwoSum
  low = sum_error + product_error + remainder + turns * kTwoPiLow;
}

}  // namespace birkhoff_cart
