// The local error a Gauss–Legendre collocation step makes on the linearisation of ẇ = F(w, t)
// (docs/birkhoffian.md §12.1, eqs. (B.54)–(B.55)): the part of the error the embedded estimate (B.37) cannot
// see, which the adaptive control adds to it, weighted by kLinearModeWeight (B.55).
//
// The estimate (B.37) is the collocation polynomial's defect at the step's ends, which vanishes
// identically on linear autonomous dynamics. A stiff, nearly linear mode (a stiff hinge spring,
// ringing after the start) is then invisible to it when a step jumps over it, although the s-stage
// member's stability function R_s (|R_s(∞)| = 1) carries the mode on undamped where the true motion
// decays. On very_stiff_hinge, birkhoff_gauss8 at 1e-9 m grew its step from 0.02 s to 0.41 s at
// t ≈ 2.4 s (h·ρ(J) from about 8 to 165) with ê at 2–5 % of its aim, and the position error of B
// jumped from 2e-11 m to 1.5e-8 m, 14× the tolerance.
//
// For ẇ = J w + c the exact step moves w by h φ₁(hJ) F(w) and the member by h ψ(hJ) F(w), with
// φ₁(z) = (eᶻ − 1)/z and ψ(z) = (R_s(z) − 1)/z, R_s the (s, s) Padé approximant of eᶻ. Their
// difference is the top-right column of R_s(Ẑ) − exp(Ẑ) for the bordered matrix Ẑ = [[hJ, hF],
// [0, 0]] (for f(0) = 1 that column of f(Ẑ) is (f(hJ) − I)(hJ)⁻¹ hF). The next diagonal
// approximant R_{s+1} stands in for exp:
//
//   e_L = [R_s(Ẑ) − R_{s+1}(Ẑ)]_{1:n, n+1},   Ẑ = [[hJ, hF], [0, 0]]                               (B.54)
//
// from the step's start rate F = F(w, tₖ) and the stage solve's J = ∂F/∂w. R_s(z) − eᶻ =
// −c_s z^{2s+1} + …, c_s = (s!)² / ((2s)! (2s + 1)!), and R_{s+1}(z) − eᶻ = O(z^{2s+3}): e_L is the
// member's own linearised local error to leading order, O(h^{2s+1}) on smooth motion; where
// h·ρ(J) ≫ 1 it reads about twice the stepped-over mode's amplitude (R_s → (−1)^s, R_{s+1} →
// (−1)^{s+1}, e^{hλ} → 0). Cost, where computed: s products of (n + 1)² matrices, two LU
// factorisations and s + 1 matrix–vector products.
#pragma once

#include <Eigen/Core>
#include <Eigen/LU>
#include <array>
#include <cmath>

namespace birkhoff_cart {

/// c_s of (B.54): R_s(z) − eᶻ = −c_s z^{2s+1} + O(z^{2s+2}) for the s-stage Gauss member [-].
constexpr double linear_mode_error_constant(int stages) {
  double squared_factorial = 1.0;  // (s!)²
  for (int k = 2; k <= stages; ++k) squared_factorial *= static_cast<double>(k) * k;
  double even_factorial = 1.0;  // (2s)!
  for (int k = 2; k <= 2 * stages; ++k) even_factorial *= k;
  return squared_factorial / (even_factorial * even_factorial * (2 * stages + 1));
}

/// w_L of (B.55): the weight of e_L in the adaptive control's estimate ê = ‖e + w_L e_L‖ [-]. The
/// control must see a ringing stiff mode before it jumps over it, not resolve the mode to the
/// tolerance: a steering mode reaches the position of B at a small fraction of its amplitude, and
/// with w_L = 1 very_stiff_hinge ended 10⁻⁴–10⁻⁶ of its tolerance for up to 45 % more steps. From 10⁻⁵ on
/// (swept over 10⁻⁶ … 1: CHANGELOG 0.6.0), very_stiff_hinge ends within twice its tolerance for every
/// Gauss member, for at most 2 % more evaluations; off the two hinges no shipped scene's grid moves.
constexpr double kLinearModeWeight = 1e-5;

/// e_L of (B.54) for the s-stage Gauss member over h [s], from J = ∂F/∂w [1/s] and the start rate F
/// [w's units/s], where its leading term c_s ‖(hJ)^{2s} hF‖∞ exceeds `negligible` (w's units);
/// zero (not computed) below it, where it could not change what it is added to. The leading term
/// costs 2s products of hJ with a vector.
template <int Stages, int N>
Eigen::Matrix<double, N, 1> linear_mode_error(const Eigen::Matrix<double, N, N>& jacobian,
                                              const Eigen::Matrix<double, N, 1>& start_rate, double h, double negligible) {
  static_assert(Stages >= 1, "a Gauss member has at least one stage");
  using Bordered = Eigen::Matrix<double, N + 1, N + 1>;
  using Column = Eigen::Matrix<double, N + 1, 1>;
  const Eigen::Matrix<double, N, N> step_jacobian = h * jacobian;  // hJ [-]
  Eigen::Matrix<double, N, 1> leading = h * start_rate;
  for (int k = 0; k < 2 * Stages; ++k) leading = (step_jacobian * leading).eval();
  if (!(linear_mode_error_constant(Stages) * leading.cwiseAbs().maxCoeff() > negligible)) {
    return Eigen::Matrix<double, N, 1>::Zero();
  }

  Bordered bordered = Bordered::Zero();  // Ẑ
  bordered.template topLeftCorner<N, N>() = step_jacobian;
  bordered.template topRightCorner<N, 1>() = h * start_rate;
  std::array<Bordered, Stages + 2> powers;  // Ẑ¹ … Ẑ^{s+1}, shared by both approximants
  powers[1] = bordered;
  for (int j = 2; j <= Stages + 1; ++j) powers[j] = (powers[j - 1] * bordered).eval();
  // R_m(Ẑ) e_{n+1} = P_m(−Ẑ)⁻¹ P_m(Ẑ) e_{n+1}, P_m(z) = Σⱼ (2m − j)! m! / ((2m)! j! (m − j)!) zʲ.
  auto stability_column = [&powers](int m) {
    Bordered backward = Bordered::Identity();  // P_m(−Ẑ)
    Column forward = Column::Unit(N);          // P_m(Ẑ) e_{n+1}
    double coefficient = 1.0;
    for (int j = 1; j <= m; ++j) {
      coefficient *= static_cast<double>(m - j + 1) / (static_cast<double>(j) * (2 * m - j + 1));
      backward += ((j % 2 == 0) ? coefficient : -coefficient) * powers[j];
      forward += coefficient * powers[j].col(N);
    }
    return Column(backward.partialPivLu().solve(forward));
  };
  return (stability_column(Stages) - stability_column(Stages + 1)).template head<N>();
}

}  // namespace birkhoff_cart
