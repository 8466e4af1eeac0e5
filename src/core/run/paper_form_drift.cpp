#include "birkhoff_cart/core/run/paper_form_drift.h"

#include <cmath>
#include <memory>
#include <sstream>

#include "birkhoff_cart/core/physics/cart_model.h"
#include "birkhoff_cart/core/integrators/deterministic_math.h"
#include "birkhoff_cart/core/physics/effects.h"
#include "birkhoff_cart/core/cart_binding/cart_stepper.h"

namespace birkhoff_cart {
namespace {

constexpr int kProbeSteps = 8;  // steps averaged for δ (δ·8 stays far above round-off for h ≥ 1e-4 s)

}  // namespace

double paper_form_momentum_change_per_step(const Scene& scene) {
  // The factor is the chart's, not the cart's: the default physical cart probes it (the paper's
  // special case has a singular M at χ = 0, where the probe coasts).
  const CartModel model{CartParameters{}};
  const EffectSet no_loads;
  IntegratorSettings settings = scene.integrator;
  settings.step_control = StepControl::kFixed;  // the chart's factor per step of h, whatever the run's control
  settings.global_error_estimate = false;       // the adaptive control's; the probe steps at fixed h
  const std::unique_ptr<CartStepper> stepper = make_cart_stepper(settings, model, no_loads);
  CartState state;  // straight ahead at 1 m/s: p = M(0) ω is constant along the exact motion
  state.time = scene.initial_state.time;
  state.forward_speed = 1.0;
  StepStatistics statistics;
  const double p_start = model.momentum(0.0, Vector2<double>(1.0, 0.0))(0);
  for (int k = 0; k < kProbeSteps; ++k) stepper->step(state, settings.step_size, statistics);
  const double p_end = model.momentum(state.steering_angle, Vector2<double>(state.forward_speed, state.steering_rate))(0);
  return deterministic::pow(p_end / p_start, 1.0 / kProbeSteps) - 1.0;
}

double paper_form_momentum_growth(const Scene& scene, double duration) {
  const double delta = paper_form_momentum_change_per_step(scene);
  const double steps = duration / scene.integrator.step_size;
  return std::expm1(steps * std::log1p(delta));
}

std::string paper_form_drift_warning(const Scene& scene) {
  if (scene.integrator.birkhoffian_form != BirkhoffianForm::kPaper) return "";
  // The drift is a fixed step's: under a step control the member's own steps follow the tolerance,
  // and integrator.step_size is the rows' interval, which says nothing of them.
  if (scene.integrator.step_control != StepControl::kFixed) return "";
  const double growth = paper_form_momentum_growth(scene, scene.duration);
  if (!(std::abs(growth) > kPaperFormDriftWarningThreshold)) return "";
  std::ostringstream message;
  message.precision(3);
  message << "warning: the paper's e^t form with " << scene.integrator.name << " at h = " << scene.integrator.step_size
          << " s multiplies the momenta by about 1 + " << paper_form_momentum_change_per_step(scene)
          << " per step regardless of the motion: over " << scene.duration << " s they drift by " << 100.0 * growth
          << " % and the energy by at least twice that (10x on the jackknife whirl); use birkhoffian_form: "
             "autonomous for long runs (docs/birkhoffian.md §10)";
  return message.str();
}

}  // namespace birkhoff_cart
