// The integrator registry: one table of the members (integrator_members.h; the rows are built in
// src/core/cart_binding/integrator_registry.cpp) with what each one is and how it is built. Whatever
// lists, checks or builds a member reads it: the scene loader, make_cart_stepper, cart_simulate's
// --help, the node, the benchmarks, the tests.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "birkhoff_cart/core/integrators/integrator_settings.h"
#include "birkhoff_cart/core/integrators/integrator_kind.h"

namespace birkhoff_cart {

class CartModel;
class CartStepper;
class EffectSet;

/// Builds a member's stepper for `model` and `effects` (both must outlive it) with `settings`
/// (its form, Newton and collocation settings, dopri5's tolerance, the reversible control's).
using CartStepperFactory = std::unique_ptr<CartStepper> (*)(const IntegratorSettings& settings,
                                                            const CartModel& model, const EffectSet& effects);

/// One row of the registry: a member of integrator_members.h, everything but the description read
/// from its stepper type (integrator_registry.cpp). The claims (order, symmetric, reversible) are
/// checked against the steppers the factories build by integrator_registry_test (order measured)
/// and registry_properties_test (symmetry by reversal).
struct IntegratorEntry {
  const char* name = "";         ///< integrator.name, --integrator, ~integrator: Stepper::name()
  int order = 0;                 ///< order of accuracy p [-]: Stepper::kOrder (dopri5: its 5th-order solution's)
  bool symmetric = false;        ///< time-symmetric (self-adjoint) step map: Stepper::kSymmetric
  IntegratorKind kind = IntegratorKind::kExplicitRungeKutta;  ///< the family of its scheme: Stepper::kKind
  const char* description = "";  ///< one line for help texts
  CartStepperFactory make_fixed = nullptr;       ///< step_control fixed: steps of h
  CartStepperFactory make_reversible = nullptr;  ///< step_control reversible (docs/birkhoffian.md §11); null: not offered
  CartStepperFactory make_adaptive = nullptr;    ///< step_control adaptive (docs/birkhoffian.md §12); null: not offered
  /// Evaluates the s stages' right-hand sides of an iteration together, with one vector sin/cos on
  /// CPUs with AVX (vector_math.h; docs/integrators.md, "Stage evaluation").
  bool vector_stages = false;

  /// Takes step_control reversible (the symmetric Birkhoffian members).
  bool reversible() const { return make_reversible != nullptr; }
  /// Takes step_control adaptive (the Birkhoffian members: their local error estimate drives it).
  bool adaptive() const { return make_adaptive != nullptr; }
  /// Reads `tolerance` (a local error tolerance [-]) instead of stepping at h alone.
  bool takes_tolerance() const { return kind == IntegratorKind::kAdaptive; }
};

/// Every member, in the registry's order.
const std::vector<IntegratorEntry>& integrator_registry();

/// The member named `name`; nullptr when there is none.
const IntegratorEntry* find_integrator(const std::string& name);

/// The member named `name`. Throws std::invalid_argument naming it, listing the known names and
/// the closest one to a typo ("unknown integrator 'rk5' (known: …; did you mean 'rk4'?)").
const IntegratorEntry& integrator_entry(const std::string& name);

/// Every member's name, in the registry's order.
std::vector<std::string> integrator_names();

/// The names of the members that take step_control reversible, in the registry's order.
std::vector<std::string> reversible_integrator_names();

/// The names of the members that take step_control adaptive, in the registry's order.
std::vector<std::string> adaptive_integrator_names();

}  // namespace birkhoff_cart
