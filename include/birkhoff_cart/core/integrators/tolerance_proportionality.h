// From the position tolerance a run asks for to the error per unit step its control aims at
// (docs/birkhoffian.md §12.5, eq. (B.53); docs/accuracy.md §4). Private to the core library.
//
// The adaptive control keeps the member's estimate at ê ≈ τ_a·h (B.46). For the Gauss members ê is of
// order q = s + 2 while their local error is of order 2s + 1, so the global error E ends near
// C·τ_a^{p/(q−1)}, far below τ_a·T at loose tolerances: aiming at τ_a = τ = tolerance / horizon
// (B.48) overdelivers by 10³–10⁵. Tolerance proportionality (Higham, SIAM J. Sci. Stat. Comput. 12,
// 1991) aims instead at
//
//   τ_a = max(τ, min(c·(τ·1 s)^α / 1 s, L·τ, τ_max)),   τ_max = 5·10⁻³ /s                       (B.53)
//
// α, c and the cap L measured per member on the shipped scenes (scripts/python/tolerance_proportionality.py,
// the table in accuracy.md §4.3), with ê's passive coordinates measured absolutely (error_estimate.h):
// gauss4 α = 0.90, c = 3, L = 100; gauss6 α = 0.70, c = 1, L = 1000; gauss8 α = 0.60, c = 1, L = 1000.
// α < 1 follows the estimate's lower order (β ≈ p/(q − 1) in E ∝ τ_a^β on smooth scenes); the cap L
// holds at the tight end on the stiff hinges, where the Gauss members' error drops to the stage order
// (order reduction), the estimate sees it, and a looser aim ends beyond twice the tolerance (gauss8
// with L = 4000 and τ_max = 10⁻²: very_stiff_hinge at 1e-9 m 2.96×); τ_max holds at the loose end,
// where the estimate leaves its asymptotic range at large steps.
// Members not listed keep τ_a = τ.
#pragma once

#include <algorithm>
#include <cmath>

#include "birkhoff_cart/core/integrators/deterministic_math.h"
#include "birkhoff_cart/core/integrators/gauss_collocation.h"

namespace birkhoff_cart {

/// α and c of (B.53) for a member under the adaptive control; the default: τ_a = τ.
template <class Stepper>
struct AdaptiveToleranceProportionality {
  static constexpr double kExponent = 1.0;  ///< α [-]
  static constexpr double kScale = 1.0;     ///< c [-] (τ in 1/s)
  static constexpr double kCap = 1.0;       ///< L [-]
};

/// The Gauss members with s ≥ 2 (ê of order s + 2 below the error's 2s + 1); s = 1 (birkhoff2: ê of
/// order 3, its own error's order) keeps τ.
template <int Stages>
struct AdaptiveToleranceProportionality<GaussCollocation<Stages>> {
  //                                            s = 1  s = 2  s = 3  s = 4
  static constexpr double kExponents[] = {1.0, 1.0, 0.90, 0.70, 0.60};
  static constexpr double kScales[] = {1.0, 1.0, 3.0, 1.0, 1.0};
  static constexpr double kCaps[] = {1.0, 1.0, 100.0, 1000.0, 1000.0};
  static constexpr double kExponent = kExponents[Stages];
  static constexpr double kScale = kScales[Stages];
  static constexpr double kCap = kCaps[Stages];
};

/// The largest aim τ_max of (B.53) that loosens τ [1/s].
constexpr double kLargestLoosenedAim = 5e-3;

/// τ_a of (B.53) [1/s] for the error per unit step τ [1/s] (> 0).
template <class Proportionality>
double aimed_error_per_unit_step(double error_per_unit_step) {
  const double loosened = std::min({Proportionality::kScale * deterministic::pow(error_per_unit_step, Proportionality::kExponent),
                                    Proportionality::kCap * error_per_unit_step, kLargestLoosenedAim});
  return std::max(error_per_unit_step, loosened);
}

}  // namespace birkhoff_cart
