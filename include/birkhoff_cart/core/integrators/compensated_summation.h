// Compensated summation of the state update (docs/birkhoffian.md §10.3, eq. (B.34)): the state is
// carried as value plus remainder (x, r) and updated with Knuth's TwoSum, x⁺ + r⁺ = x + (r + Δ)
// exactly, so that the round-off of adding a small increment to a large coordinate does not
// accumulate over millions of steps.
#pragma once

#include <Eigen/Core>
#include <type_traits>

#include "birkhoff_cart/core/integrators/birkhoffian_system.h"

namespace birkhoff_cart {

/// s + err = a + b exactly (Knuth's TwoSum; no ordering of |a|, |b| needed).
inline void two_sum(double a, double b, double& sum, double& error) {
  sum = a + b;
  const double b_virtual = sum - a;
  error = (a - (sum - b_virtual)) + (b - b_virtual);
}

/// x⁺ + r⁺ = x + increment, componentwise TwoSum (the increment already holds the old remainder).
/// For AD jets (a differentiated step) the remainder is zero.
template <class Vector>
void add_compensated(const Vector& x, const Vector& increment, Vector& sum, Vector& remainder) {
  sum = x + increment;
  if constexpr (std::is_same<typename Vector::Scalar, double>::value) {
    for (Eigen::Index k = 0; k < x.size(); ++k) two_sum(x(k), increment(k), sum(k), remainder(k));
  } else {
    remainder = Vector::Constant(typename Vector::Scalar(0.0));
  }
}

/// A time carried as high + low part, so that a sum of millions of unequal steps keeps every bit [s].
class CompensatedTime {
 public:
  void set(double t) {
    high_ = t;
    low_ = 0.0;
  }
  double value() const { return high_ + low_; }
  /// t − this [s], with the low part.
  double until(double t) const { return (t - high_) - low_; }
  /// this += h [s] (TwoSum, renormalized).
  void add(double h) {
    double carry = 0.0;
    two_sum(high_, h, high_, carry);
    low_ += carry;
    const double sum = high_ + low_;
    low_ -= sum - high_;
    high_ = sum;
  }

 private:
  double high_ = 0.0;  ///< [s]
  double low_ = 0.0;   ///< [s]
};

/// A point (z, y) with the round-off remainders that compensated summation carries between steps.
template <class System>
struct CompensatedPoint {
  StateVector<System, double> z = StateVector<System, double>::Zero();
  StateVector<System, double> z_remainder = StateVector<System, double>::Zero();
  PassiveVector<System, double> y = PassiveVector<System, double>::Zero();
  PassiveVector<System, double> y_remainder = PassiveVector<System, double>::Zero();
};

}  // namespace birkhoff_cart
