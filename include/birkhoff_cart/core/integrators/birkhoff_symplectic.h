// Generalized K(z,t)-symplectic difference schemes for Birkhoffian systems (Su's scheme, paper
// eqs. (12)–(14); docs/birkhoffian.md §4, eqs. (B.12)–(B.17), and §10).
//
// birkhoff2 — the α mapping is the Darboux chart w = D(z, t) (D_zᵀ K₀ D_z = K) composed with the
// Euler-centred (Cayley/Poincaré) generating-function map; with the series (13) truncated after its
// first term the scheme is the midpoint rule in the chart, i.e. one-stage Gauss collocation:
// GaussCollocation<1> (gauss_collocation.h), solved by fixed-point iteration from extrapolated
// starting values, with compensated summation when the caller carries remainders.
//
// Compositions Φ_h = Φ_{γ_m h} ∘ … ∘ Φ_{γ_1 h} of birkhoff2 (GNI §II.4, §V.3): a composition of
// K(z,t)-symplectic maps between consecutive times is K(z,t)-symplectic, and a symmetric composition
// of a symmetric order-2 map with these weights has the stated order (eq. (B.17)):
//   birkhoff4           triple jump (Yoshida 1990, Suzuki 1990), 3 sub-steps, order 4;
//   birkhoff4_suzuki    Suzuki's fractal 5-stage, γ = (p, p, 1 − 4p, p, p), p = 1/(4 − 4^{1/3}), order 4,
//                       about 4× smaller error constant than the triple jump (GNI eq. (V.3.6));
//   birkhoff6_kahan_li  Kahan & Li 1997 s9odr6a, 9 sub-steps, order 6 (GNI eq. (V.3.11));
//   birkhoff8_kahan_li  Kahan & Li 1997 s17odr8a, 17 sub-steps, order 8 (GNI eq. (V.3.12)).
// The sub-steps share one memory of stage derivatives, so each starts from a linear extrapolation of
// the two sub-steps before it, and one Jacobian with a Newton matrix per distinct sub-step size.
//
// Local error estimate: the sum of the sub-steps' error vectors (gauss_collocation.h, eq. (B.37)),
// normed once per composed step. The sub-steps' leading O((γᵢh)³) terms cancel in the sum because
// Σγᵢ³ = 0 (the compositions' third-order condition), the rest does not: ê = O(h⁴) (measured slope 4.0
// on the paper case, test/unit/error_estimate_test.cpp), a conservative bound of an O(h^{p+1}) error.
// A sub-step's F(w⁺) is the next sub-step's F(w) (first same as last): one extra evaluation each.
#pragma once

#include <array>
#include <cmath>

#include "birkhoff_cart/core/integrators/gauss_collocation.h"
#include "birkhoff_cart/core/integrators/integrator_kind.h"

namespace birkhoff_cart {

/// birkhoff2: the one-stage member.
using BirkhoffSymplectic2 = GaussCollocation<1>;

/// Weights of the symmetric compositions (γ₁ … γ_m, Σγ = 1).
struct TripleJumpWeights {
  static constexpr int kSubsteps = 3;
  static constexpr int kOrder = 4;
  static const char* name() { return "birkhoff4"; }
  static std::array<double, kSubsteps> weights() {
    const double outer = 1.0 / (2.0 - std::cbrt(2.0));  // γ₁ = γ₃ ≈ 1.3512
    return {outer, 1.0 - 2.0 * outer, outer};
  }
};
struct SuzukiFiveWeights {
  static constexpr int kSubsteps = 5;
  static constexpr int kOrder = 4;
  static const char* name() { return "birkhoff4_suzuki"; }
  static std::array<double, kSubsteps> weights() {
    const double p = 1.0 / (4.0 - std::cbrt(4.0));  // ≈ 0.41449
    return {p, p, 1.0 - 4.0 * p, p, p};
  }
};
struct KahanLiSixWeights {
  static constexpr int kSubsteps = 9;
  static constexpr int kOrder = 6;
  static const char* name() { return "birkhoff6_kahan_li"; }
  static std::array<double, kSubsteps> weights() {
    constexpr double g1 = 0.39216144400731413927925056, g2 = 0.33259913678935943859974864,
                     g3 = -0.70624617255763935980996482, g4 = 0.08221359629355080023149045,
                     g5 = 0.79854399093482996339895035;
    return {g1, g2, g3, g4, g5, g4, g3, g2, g1};
  }
};
struct KahanLiEightWeights {
  static constexpr int kSubsteps = 17;
  static constexpr int kOrder = 8;
  static const char* name() { return "birkhoff8_kahan_li"; }
  static std::array<double, kSubsteps> weights() {
    constexpr double g1 = 0.13020248308889008087881763, g2 = 0.56116298177510838456196441,
                     g3 = -0.38947496264484728640807860, g4 = 0.15884190655515560089621075,
                     g5 = -0.39590389413323757733623154, g6 = 0.18453964097831570709183254,
                     g7 = 0.25837438768632204729397911, g8 = 0.29501172360931029887096624,
                     g9 = -0.60550853383003451169892108;
    return {g1, g2, g3, g4, g5, g6, g7, g8, g9, g8, g7, g6, g5, g4, g3, g2, g1};
  }
};

/// Symmetric composition of birkhoff2 with the given weights.
template <class Weights>
class BirkhoffComposition {
 public:
  static constexpr int kOrder = Weights::kOrder;
  static constexpr bool kSymmetric = true;
  static constexpr IntegratorKind kKind = IntegratorKind::kComposition;
  /// ê ∝ h⁴: the sub-steps' O((γᵢh)³) terms cancel (Σγᵢ³ = 0); the error-per-step control's exponent.
  static constexpr int kErrorEstimateOrder = 4;
  static const char* name() { return Weights::name(); }
  template <class System>
  using Memory = CollocationMemory<System, 1>;

  BirkhoffComposition() = default;
  explicit BirkhoffComposition(const NewtonSettings& newton) : base_(newton) {}
  explicit BirkhoffComposition(const CollocationSettings& settings) : base_(settings) {}

  template <class System, class S>
  void step(const System& system, StateVector<System, S>& z, PassiveVector<System, S>& y, double t, double h,
            StepStatistics& statistics) const {
    statistics.newton_iterations_last_step = 0;
    const StateVector<System, S> z_start = z;
    const PassiveVector<System, S> y_start = y;
    LocalErrorVectors<System, S> error;  // Σ of the sub-steps' error vectors
    double time = t;  // start of the current sub-step [s]
    for (double gamma : Weights::weights()) {
      base_.advance(system, z, y, time, gamma * h, statistics, &error);  // z ← Φ_{γh}(z) from `time`
      time += gamma * h;
    }
    if (base_.settings().estimate_local_error) {
      record_local_error_estimate(statistics, local_error_norm<System, S>(z_start, y_start, error.z, error.y));
    }
  }

  template <class System>
  void advance_compensated(const System& system, CompensatedPoint<System>& point, CollocationMemory<System, 1>& memory,
                           double t, double h, StepStatistics& statistics) const {
    const StateVector<System, double> z_start = point.z;
    const PassiveVector<System, double> y_start = point.y;
    LocalErrorVectors<System, double> error;  // Σ of the sub-steps' error vectors
    double time = t;
    for (double gamma : Weights::weights()) {
      base_.advance_compensated(system, point, memory, time, gamma * h, statistics, &error);
      time += gamma * h;
    }
    if (base_.settings().estimate_local_error) {
      record_local_error_estimate(statistics, local_error_norm<System, double>(z_start, y_start, error.z, error.y));
    }
  }

 private:
  GaussCollocation<1> base_;
};

using BirkhoffSymplectic4 = BirkhoffComposition<TripleJumpWeights>;

}  // namespace birkhoff_cart
