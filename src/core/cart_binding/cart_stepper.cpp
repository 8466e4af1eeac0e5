// make_cart_stepper: checks the settings every member shares and builds the named member of the
// registry (integrator_registry.cpp) under the step control the settings ask for.
#include "birkhoff_cart/core/cart_binding/cart_stepper.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "birkhoff_cart/core/support/closest_name.h"
#include "birkhoff_cart/core/integrators/adaptive_refusal.h"
#include "step_checks.h"

namespace birkhoff_cart {

std::unique_ptr<CartStepper> make_cart_stepper(const IntegratorSettings& settings, const CartModel& model,
                                               const EffectSet& effects) {
  stepper_checks::require_valid_step_size(settings.step_size);
  if (settings.max_newton_iterations < 1) {
    throw std::invalid_argument("max_newton_iterations must be >= 1, got " +
                                std::to_string(settings.max_newton_iterations));
  }
  if (!(settings.newton_tolerance > 0.0) || !std::isfinite(settings.newton_tolerance)) {
    throw std::invalid_argument("newton_tolerance must be finite and > 0");
  }
  if (settings.global_error_estimate && settings.step_control != StepControl::kAdaptive) {
    throw std::invalid_argument(std::string("global_error_estimate follows the grid of step_control 'adaptive', not '") +
                                to_string(settings.step_control) + "'");
  }
  if (settings.step_control == StepControl::kReversible) {
    const IntegratorEntry* member = find_integrator(settings.name);
    if (member == nullptr || !member->reversible()) {
      throw std::invalid_argument("step_control 'reversible' is for the symmetric Birkhoffian members (" +
                                  name_list(reversible_integrator_names()) + "), not '" + settings.name + "'");
    }
    return member->make_reversible(settings, model, effects);
  }
  if (settings.step_control == StepControl::kAdaptive) {
    const IntegratorEntry* member = find_integrator(settings.name);
    if (member == nullptr || !member->adaptive()) {
      throw std::invalid_argument(adaptive_refusal_message(settings.name));
    }
    return member->make_adaptive(settings, model, effects);
  }
  return integrator_entry(settings.name).make_fixed(settings, model, effects);
}

}  // namespace birkhoff_cart
