// What a simulation compares itself against (Scene::reference), computed only when a scene asks:
//  - paper_analytic: the closed-form solution of the paper's special case (docs eq. (3.9)),
//  - shadow_run: a second integration of the same scene with another integrator (shadow_reference.h).
#pragma once

#include <cstdint>
#include <memory>

#include "birkhoff_cart/core/physics/cart_model.h"
#include "birkhoff_cart/core/integrators/diagnostics.h"
#include "birkhoff_cart/core/physics/effects.h"
#include "birkhoff_cart/core/cart_binding/cart_stepper.h"
#include "birkhoff_cart/core/scene/scene.h"
#include "birkhoff_cart/core/physics/state.h"

namespace birkhoff_cart {

/// The paper's special case μ = μ1 = 0, ν = 1, l = 1 with χ(t₀) = t₀, ω2 = 1, ω1(t₀) sin t₀ = 1
/// (docs eq. (3.9)): χ = t, ω1 = 1/sin t, θ = θ₀ + (t − t₀), π1 = π1₀ + ln tan(t/2) − ln tan(t₀/2)
/// and, with φ = θ₀ − t₀ (so θ + χ = 2t + φ), the hinge position from ẋ = cos(2t + φ)/sin t,
/// ẏ = sin(2t + φ)/sin t (cos 2t = 1 − 2 sin²t, sin 2t = 2 sin t cos t):
///   x = x₀ + cos φ [ln tan(s/2) + 2 cos s]_{t₀}^{t} − sin φ [2 sin s]_{t₀}^{t},
///   y = y₀ + cos φ [2 sin s]_{t₀}^{t} + sin φ [ln tan(s/2) + 2 cos s]_{t₀}^{t}.
/// Valid on 0 < t < π (the mass matrix is singular at χ = kπ).
struct PaperAnalyticSolution {
  CartState initial;  ///< the state at t₀ (must lie on the solution: see matches())

  /// The analytic state at time t [s] (wheel angles, W and I2 are left at their initial values).
  CartState at(double time) const;
  /// Whether `state` lies on the analytic family (χ = t, ω2 = 1, ω1 sin t = 1, within 1e-12).
  static bool matches(const CartState& state);
};

/// A reference the simulation is compared against. Transactional like the simulation: a step
/// that throws leaves it unchanged.
class ReferenceSolution {
 public:
  virtual ~ReferenceSolution() = default;
  /// Advance in lockstep with the simulation from time t to `next_time` [s] (h = next_time − t).
  virtual void step(double next_time) = 0;
  /// Back to the initial state.
  virtual void reset() = 0;
  /// A command input is about to change at the simulation's time `time` [s] (the reference has
  /// been stepped to it): a reference that integrates the commands must reach `time` with the old
  /// command held. Default: nothing.
  virtual void command_changes(double /*time*/) {}
  /// The simulation jumped at `state.time` (an end-stop impact or release, docs/actuators.md §3.3;
  /// the reference has been stepped to that time): continue from the simulation's `state`, so the
  /// reference judges the integration error since the latest event. Default: std::logic_error (a
  /// closed-form reference cannot follow; the scene loader refuses end stops with it).
  virtual void restart_at(const CartState& state);
  /// Fills the reference fields of `diagnostics` for the simulated `state`.
  virtual void compare(const CartState& state, Diagnostics& diagnostics) const = 0;
};

/// Fills the reference fields of `diagnostics`: position, heading and arc-length errors of `state`
/// against `reference`.
void compare_states(const CartState& state, const CartState& reference, Diagnostics& diagnostics);

/// Builds the scene's reference (nullptr for ReferenceSettings::Kind::kNone). The model and effects
/// must outlive it. Throws std::invalid_argument when the scene cannot have that reference (e.g.
/// paper_analytic without the paper's special case or off its analytic initial state).
std::unique_ptr<ReferenceSolution> make_reference_solution(const Scene& scene, const CartModel& model,
                                                           const EffectSet& effects);

}  // namespace birkhoff_cart
