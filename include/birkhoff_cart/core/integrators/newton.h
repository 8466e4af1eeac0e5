// Newton's method for small fixed-size nonlinear systems F(x) = 0 with the Jacobian by forward-mode
// automatic differentiation (exact to round-off, never finite differences). docs/birkhoffian.md §5.
//
// The residual is given as a *factory*: `make_residual(parameter_cast)` returns a functor whose
// templated call operator evaluates F on unknowns of any scalar type T. The factory decouples the
// scalar of the unknowns from that of the data the residual closes over (e.g. the previous step's
// state): when the data themselves are AD jets (the whole step map is being differentiated),
//   1. the value iteration runs on plain doubles, with the Jacobian from Jet<N>, on the value parts
//      of the data (`make_residual(ValueParameters{})`), then
//   2. one or two extra Newton updates x ← x − J⁻¹ F(x) are applied in the jet type with the
//      converged value Jacobian J (`make_residual(FullParameters{})`). At the converged value this
//      update maps the derivative parts to ẋ = −J⁻¹ ∂F/∂(data) · (data)˙, the implicit-function-
//      theorem derivative, exactly (the update is linear in the derivative parts).
//
// Usage (S = double or Jet<M>; `data` of type Matrix<S, …>):
//   auto factory = [&](auto cast) {
//     return [&, cast](const auto& x) {           // x: Matrix<T, N, 1>, T = double, Jet<N> or S
//       using T = typename std::decay_t<decltype(x)>::Scalar;
//       const auto d = cast.template apply<T>(data);  // data with scalar T (values or full)
//       return (x - d).eval();
//     };
//   };
//   solve_newton<N>(factory, x, settings, time, statistics);
#pragma once

#include <Eigen/Core>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <string>
#include <limits>
#include <sstream>
#include <type_traits>

#include "birkhoff_cart/core/integrators/autodiff.h"
#include "birkhoff_cart/core/integrators/diagnostics.h"
#include "birkhoff_cart/core/integrators/step_error.h"

namespace birkhoff_cart {

/// Settings of the Newton iteration (IntegratorSettings::newton_tolerance/max_newton_iterations).
struct NewtonSettings {
  double tolerance = 1e-14;  ///< on the scaled update ‖Δx‖∞ / max(‖x‖∞, 1e-300) [-]
  int max_iterations = 30;   ///< value iterations before StepError [-]
};

/// The value parts of a matrix of doubles or AD jets, as doubles.
template <class Matrix>
Eigen::Matrix<double, Matrix::RowsAtCompileTime, Matrix::ColsAtCompileTime> values_of(const Matrix& m) {
  Eigen::Matrix<double, Matrix::RowsAtCompileTime, Matrix::ColsAtCompileTime> v(m.rows(), m.cols());
  for (Eigen::Index i = 0; i < m.rows(); ++i)
    for (Eigen::Index j = 0; j < m.cols(); ++j) v(i, j) = value_of(m(i, j));
  return v;
}

/// Parameter cast for the value iteration: data → their value parts, as constants of type T.
struct ValueParameters {
  template <class T, class Matrix>
  Eigen::Matrix<T, Matrix::RowsAtCompileTime, Matrix::ColsAtCompileTime> apply(const Matrix& m) const {
    return values_of(m).template cast<T>();
  }
  template <class T, class Scalar>
  T scalar(const Scalar& s) const {
    return T(value_of(s));
  }
};

/// Parameter cast for the jet refinement: data unchanged (T is then the data's own scalar type).
struct FullParameters {
  template <class T, class Matrix>
  Eigen::Matrix<T, Matrix::RowsAtCompileTime, Matrix::ColsAtCompileTime> apply(const Matrix& m) const {
    return m.template cast<T>();
  }
  template <class T, class Scalar>
  T scalar(const Scalar& s) const {
    return T(s);
  }
};

namespace newton_detail {

/// Inner AD type for the value Jacobian. Deliberately a different type from Jet<N> (unaligned
/// derivative storage) so that it can never be confused with an outer jet S = Jet<N> in overloads.
template <int N>
using JacobianJet = Eigen::AutoDiffScalar<Eigen::Matrix<double, N, 1, Eigen::DontAlign>>;

template <int N>
std::string describe_failure(const char* what, double time, int iterations, double residual_norm) {
  std::ostringstream message;
  message << "Newton's method " << what << " at t = " << time << " s after " << iterations
          << " iterations (residual max-norm " << residual_norm << ")";
  return message.str();
}

}  // namespace newton_detail

/// Solves F(x) = 0 for x ∈ R^N in place, starting from the given x. Returns the number of value
/// iterations (also added to statistics.newton_iterations_last_step, which the stepper resets). Counts each F evaluation as one right-hand-side evaluation and each iteration as a
/// Newton iteration in `statistics`. Throws StepError (naming `time` [s] and the residual) when an
/// iterate or residual is not finite, the Jacobian is singular, or there is no convergence within
/// settings.max_iterations.
///
/// Convergence, on scaled updates δᵢ = ‖Δx⁽ⁱ⁾‖∞ / ‖x‖∞: stop when the error left after the update
/// just applied is below tol. That error is estimated as δᵢ²/δᵢ₋₁ once the iteration contracts
/// (δᵢ ≤ δᵢ₋₁/10): for quadratic convergence this bounds C δᵢ² from above, for linear convergence
/// with rate ρ ≤ 0.1 it is ρ δᵢ, within 10 % of the true ρ δᵢ/(1 − ρ). So the accepted iterate is
/// at the tolerance (1e-14: near machine precision) without an extra Newton iteration. Also
/// accepted: δᵢ ≤ tol, and a round-off floor (δᵢ ≤ 1e3·tol and no longer halving).
template <int N, class ResidualFactory, class S>
int solve_newton(const ResidualFactory& make_residual, Eigen::Matrix<S, N, 1>& x, const NewtonSettings& settings,
                 double time, StepStatistics& statistics) {
  using Jacobian = Eigen::Matrix<double, N, N>;
  using JetN = newton_detail::JacobianJet<N>;
  using JetVector = Eigen::Matrix<JetN, N, 1>;
  const auto value_residual = make_residual(ValueParameters{});

  Eigen::Matrix<double, N, 1> x_value = values_of(x);
  Jacobian jacobian;
  double previous_update = std::numeric_limits<double>::infinity();
  int iterations = 0;
  Eigen::PartialPivLU<Jacobian> lu;
  // |det J| relative to Hadamard's bound ∏ᵢ ‖Jᵢ‖₂ (≥ |det J|): a cheap, scale-invariant test of
  // singularity for these small matrices [-].
  constexpr double kSingularDeterminantRatio = 1e-14;
  while (true) {
    // F(x⁽ⁱ⁾) and J = ∂F/∂x (x⁽ⁱ⁾) in one forward-mode sweep, x seeded with the identity.
    JetVector x_jet;
    for (int i = 0; i < N; ++i) {
      x_jet(i).value() = x_value(i);
      x_jet(i).derivatives() = Eigen::Matrix<double, N, 1, Eigen::DontAlign>::Unit(i);
    }
    const JetVector f_jet = value_residual(x_jet);
    ++statistics.rhs_evaluations;
    Eigen::Matrix<double, N, 1> f;
    for (int i = 0; i < N; ++i) {
      f(i) = f_jet(i).value();
      jacobian.row(i) = f_jet(i).derivatives().transpose();
    }
    const double residual_norm = f.template lpNorm<Eigen::Infinity>();
    if (!f.allFinite() || !jacobian.allFinite()) {
      throw StepError(newton_detail::describe_failure<N>("met a non-finite residual or Jacobian", time, iterations,
                                                         residual_norm));
    }
    if (iterations >= settings.max_iterations) {
      throw StepError(newton_detail::describe_failure<N>("did not converge", time, iterations, residual_norm));
    }
    lu.compute(jacobian);
    const double hadamard_bound = jacobian.rowwise().norm().prod();
    if (!(std::abs(lu.determinant()) > kSingularDeterminantRatio * hadamard_bound)) {
      throw StepError(newton_detail::describe_failure<N>("met a singular Jacobian", time, iterations, residual_norm));
    }
    // x⁽ⁱ⁺¹⁾ ← x⁽ⁱ⁾ − J⁻¹ F(x⁽ⁱ⁾)
    const Eigen::Matrix<double, N, 1> update = lu.solve(f);
    x_value -= update;
    ++iterations;
    ++statistics.newton_iterations_total;
    if (!x_value.allFinite()) {
      throw StepError(newton_detail::describe_failure<N>("produced a non-finite iterate", time, iterations,
                                                         residual_norm));
    }
    const double scale = std::max(x_value.template lpNorm<Eigen::Infinity>(), 1e-300);
    const double scaled_update = update.template lpNorm<Eigen::Infinity>() / scale;  // δᵢ
    const bool contracting = std::isfinite(previous_update) && scaled_update <= 0.1 * previous_update;
    const double remaining_error = contracting ? scaled_update * scaled_update / previous_update : scaled_update;
    const bool round_off_floor = scaled_update <= 1e3 * settings.tolerance && scaled_update > 0.5 * previous_update;
    previous_update = scaled_update;
    if (scaled_update <= settings.tolerance || remaining_error <= settings.tolerance) break;  // converged
    if (round_off_floor) break;  // stagnated at the round-off floor
  }
  statistics.newton_iterations_last_step += static_cast<std::uint64_t>(iterations);

  if constexpr (std::is_same<S, double>::value) {
    x = x_value;
  } else {
    // Jet refinement: x ← x − J⁻¹ F(x) twice in the outer jet type, J the value Jacobian of the
    // last iterate (within round-off of the root). The value part moves by round-off only; the derivative
    // parts become the implicit-function-theorem derivatives.
    const auto full_residual = make_residual(FullParameters{});
    for (int i = 0; i < N; ++i) {
      x(i).value() = x_value(i);
    }
    const Jacobian inverse = lu.inverse();
    for (int refinement = 0; refinement < 2; ++refinement) {
      const Eigen::Matrix<S, N, 1> f = full_residual(x);
      ++statistics.rhs_evaluations;
      Eigen::Matrix<S, N, 1> correction;
      for (int i = 0; i < N; ++i) {
        correction(i) = S(0.0) * f(0);
        for (int j = 0; j < N; ++j) correction(i) += inverse(i, j) * f(j);
      }
      x -= correction;
    }
  }
  return iterations;
}

}  // namespace birkhoff_cart
