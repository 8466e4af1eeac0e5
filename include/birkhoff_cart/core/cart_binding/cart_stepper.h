// The type-erased integrator the simulation uses, and make_cart_stepper, which builds a member of
// the registry (integrator_registry.h) by name.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "birkhoff_cart/core/physics/cart_model.h"
#include "birkhoff_cart/core/integrators/diagnostics.h"
#include "birkhoff_cart/core/physics/effects.h"
#include "birkhoff_cart/core/integrators/integrator_settings.h"
#include "birkhoff_cart/core/cart_binding/integrator_registry.h"
#include "birkhoff_cart/core/integrators/step_error.h"  // StepError, for every user of a CartStepper
#include "birkhoff_cart/core/physics/state.h"

namespace birkhoff_cart {

/// Advances a CartState by one step of the cart's Birkhoffian system (rep (a) or (b)).
class CartStepper {
 public:
  virtual ~CartStepper() = default;
  virtual const std::string& name() const = 0;
  /// Order of accuracy (2 … 8; dopri5 reports 5).
  virtual int order() const = 0;
  /// Time-symmetric (self-adjoint) method?
  virtual bool symmetric() const = 0;
  /// Advances `state` (time included) by h [s]; adds its work to `statistics`. Throws StepError
  /// and leaves `state` untouched on failure.
  virtual void step(CartState& state, double step_size, StepStatistics& statistics) = 0;
  /// Work done once before the first step from `start`, adding to `statistics` (the reversible step
  /// control's pilot runs; nothing for the others). Throws std::invalid_argument when the settings
  /// cannot work from this start (a tolerance out of the member's reach), so that a caller refuses
  /// the scene at load instead of failing its first step.
  virtual void prepare(const CartState& /*start*/, StepStatistics& /*statistics*/) {}
  /// An instant [s] the member's own steps must end on exactly (the run's end, a caller's
  /// checkpoint): a member with its own step grid (the adaptive and reversible step controls) lands
  /// there instead of interpolating; the others step at the caller's h and ignore it.
  virtual void land_on(double /*time*/) {}
  /// Called with the state after every accepted step of the member's own grid (a step control's
  /// internal steps; nothing for the fixed-step members, whose steps are the caller's own).
  using GridObserver = std::function<void(const CartState& grid_state)>;
  virtual void observe_grid(GridObserver /*observer*/) {}
  /// The state at `time` [s] within the member's newest accepted own step, from its dense output,
  /// the run unmoved (event location: docs/python.md "solve"; a grid observer may call it for the
  /// step it is told of); the evaluations it takes are added to `work`, never to the run's counters.
  /// False when there is none there: `time` outside the newest step, no step of the current grid
  /// yet (its start, a restart at an actuator's kink), a member at fixed steps.
  virtual bool newest_step_state(double /*time*/, CartState& /*out*/, StepStatistics& /*work*/) { return false; }
};

/// Makes the registry's member settings.name (integrator_registry.h) for `model` and `effects`
/// (both must outlive it), at fixed steps or under the reversible step control. Throws
/// std::invalid_argument for an unknown name (listing the known ones), a member without the
/// control asked for, or bad settings.
std::unique_ptr<CartStepper> make_cart_stepper(const IntegratorSettings& settings, const CartModel& model,
                                               const EffectSet& effects);

}  // namespace birkhoff_cart
