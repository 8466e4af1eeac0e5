// Butcher tableaus of the s-stage Gauss–Legendre collocation methods (order 2s), s = 1 … 4, and the
// weights that extrapolate a previous step's stage derivatives to starting values (docs/birkhoffian.md
// §10, eqs. (B.30)–(B.33)).
//
// The nodes cᵢ are the roots of the shifted Legendre polynomial P_s(2c − 1), the weights
// bⱼ = ∫₀¹ ℓⱼ(τ) dτ and aᵢⱼ = ∫₀^{cᵢ} ℓⱼ(τ) dτ with ℓⱼ the Lagrange basis on the nodes (Hairer, Nørsett,
// Wanner I, §II.7; Hairer, Lubich, Wanner, GNI §II.1.3). They are computed once, in long double
// (Newton on P_s, integrals by an exact Gauss rule), not typed in: test/unit/gauss_collocation_test.cpp
// checks the simplifying conditions B(2s), C(s), D(s) that define the method.
#pragma once

#include <array>

namespace birkhoff_cart {

constexpr int kMaxGaussStages = 4;

/// The s-stage Gauss–Legendre tableau (entries beyond s are zero).
struct GaussLegendreTableau {
  int stages = 0;                                                  ///< s [-]
  std::array<double, kMaxGaussStages> nodes{};                     ///< cᵢ [-]
  std::array<double, kMaxGaussStages> weights{};                   ///< bⱼ [-]
  std::array<std::array<double, kMaxGaussStages>, kMaxGaussStages> coefficients{};  ///< aᵢⱼ [-]
  /// dᵢ = (bᵀA⁻¹)ᵢ: w⁺ = w + Σ dᵢ Zᵢ with the stage increments Zᵢ = Wᵢ − w = h Σⱼ aᵢⱼ Fⱼ, which needs no
  /// evaluation of F at the converged stages (eq. (B.33); Hairer–Wanner II §IV.8) [-].
  std::array<double, kMaxGaussStages> increment_weights{};
  /// 1 − Σᵢ dᵢ = (−1)^s: the weight of the carried remainder r in w⁺ = w + (1 − Σdᵢ) r + Σ dᵢZᵢ when the
  /// increments Zᵢ = r + h Σⱼ aᵢⱼFⱼ include it (eq. (B.34)) [-].
  double remainder_weight = 1.0;
  /// The embedded solution's weights b̂ on the s + 2 nodes {0, c₁ … c_s, 1} (eq. (B.36)):
  /// ŵ = w + h (b̂₀ F(w, tₖ) + Σᵢ b̂ᵢ Fᵢ + b̂_{s+1} F(w⁺, tₖ₊₁)), exact for polynomials of degree ≤ s
  /// (order s + 1; for s = 1 Simpson's rule, exact to degree 3). The endpoint weights are
  /// b̂₀ = β, b̂_{s+1} = (−1)^{s+1} β with β = 1/((s+1)(s+2)), the (s+2)-point Lobatto rule's endpoint
  /// weight on [0, 1]; b̂ᵢ = bᵢ − β (ℓᵢ(0) + (−1)^{s+1} ℓᵢ(1)). (The interpolatory rule on these
  /// nodes is the Gauss rule itself for s ≥ 2, b̂₀ = b̂_{s+1} = 0, and would estimate nothing.) [-]
  std::array<double, kMaxGaussStages + 2> embedded_weights{};
  /// ηⱼ with e = w⁺ − ŵ = h Σⱼ ηⱼ F(node j) on the same s + 2 nodes: η₀ = −b̂₀, ηᵢ = bᵢ − b̂ᵢ,
  /// η_{s+1} = −b̂_{s+1}, computed without cancellation. Σ ηⱼ p(τⱼ) = 0 for every polynomial p of
  /// degree ≤ s, so e = −h β (δ(0) + (−1)^{s+1} δ(1)) with δ(τ) = u'(τ) − F(u(τ)) the collocation
  /// polynomial's defect at the step's ends (eq. (B.37)) [-].
  std::array<double, kMaxGaussStages + 2> estimate_weights{};
};

/// The tableau with `stages` = 1 … 4 stages; throws std::invalid_argument otherwise.
const GaussLegendreTableau& gauss_legendre_tableau(int stages);

/// ℓⱼ(τ) for the Lagrange basis on the distinct abscissae `points`, j < count (extrapolation of stage
/// derivatives to the next step's stage times, eq. (B.32)), in double: a starting guess needs no more.
std::array<double, kMaxGaussStages> lagrange_basis_values(const std::array<double, kMaxGaussStages>& points, int count,
                                                          double tau);

/// ∫_{from}^{to} ℓⱼ(τ) dτ for the Lagrange basis polynomials ℓⱼ, j < count, on the distinct abscissae
/// `points` (any real numbers; used with stage times scaled by the new step to extrapolate stage
/// derivatives, eq. (B.32)). Exact for the polynomial degree count − 1 ≤ 3.
std::array<double, kMaxGaussStages> lagrange_basis_integrals(const std::array<double, kMaxGaussStages>& points,
                                                             int count, double from, double to);

}  // namespace birkhoff_cart
