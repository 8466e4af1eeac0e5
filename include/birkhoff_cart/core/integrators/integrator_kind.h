// The family of an integrator member's scheme (docs/integrators.md): a member states it in its type
// (`static constexpr IntegratorKind kKind`), the registry's rows read it from there.
#pragma once

namespace birkhoff_cart {

/// The family of a member's scheme (docs/integrators.md).
enum class IntegratorKind {
  kBirkhoffianCollocation,  ///< s-stage Gauss–Legendre collocation in the Darboux chart (order 2s)
  kComposition,             ///< a symmetric composition of birkhoff2 steps
  kExplicitRungeKutta,      ///< an explicit Runge–Kutta method at steps of h
  kAdaptive,                ///< an embedded pair with its own steps inside h, for `tolerance`
  kImplicitMidpoint,        ///< the implicit midpoint rule on z, solved by Newton
};

/// "Birkhoffian collocation", "composition", "explicit RK", "adaptive", "implicit midpoint".
const char* to_string(IntegratorKind kind);

/// Do the members of this family step in the Darboux chart (K(z,t)-symplectic where Λ = 0)?
constexpr bool is_birkhoffian(IntegratorKind kind) {
  return kind == IntegratorKind::kBirkhoffianCollocation || kind == IntegratorKind::kComposition;
}

}  // namespace birkhoff_cart
