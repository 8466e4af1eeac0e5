// Small helpers that let one templated formula serve both double and forward-mode automatic
// differentiation (Eigen's AutoDiffScalar): reading a value, and attaching analytic partial
// derivatives of a non-templated function (an effect) to AD inputs by the chain rule.
#pragma once

#include <Eigen/Core>
#include <unsupported/Eigen/AutoDiff>

namespace birkhoff_cart {

/// Forward-mode dual number with N derivative directions (fixed size: no heap allocation).
template <int N>
using Jet = Eigen::AutoDiffScalar<Eigen::Matrix<double, N, 1>>;

inline double value_of(double x) { return x; }
template <class Derivatives>
double value_of(const Eigen::AutoDiffScalar<Derivatives>& x) {
  return x.value();
}

/// f(inputs) as a scalar of type S, given its value and ∂f/∂inputs_j (double inputs: the value).
inline double chain(double value, const double* /*partials*/, const double* /*inputs*/, int /*count*/) {
  return value;
}
/// Extended precision (long double: the benchmark's reference runs): the value only. An effect is
/// evaluated in double, so a forced scene's loads carry double round-off even then.
inline long double chain(double value, const double* /*partials*/, const long double* /*inputs*/, int /*count*/) {
  return value;
}
template <class Derivatives>
Eigen::AutoDiffScalar<Derivatives> chain(double value, const double* partials,
                                         const Eigen::AutoDiffScalar<Derivatives>* inputs, int count) {
  Derivatives derivatives = Derivatives::Zero(inputs[0].derivatives().size());
  for (int j = 0; j < count; ++j) derivatives += partials[j] * inputs[j].derivatives();
  return Eigen::AutoDiffScalar<Derivatives>(value, derivatives);
}

}  // namespace birkhoff_cart
