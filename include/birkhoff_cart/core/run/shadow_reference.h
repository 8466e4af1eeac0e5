// The shadow-run reference (Scene::reference kind shadow_run): a second integration of the same
// scene (same model, effects and commands) with the scene's shadow integrator.
//  - dopri5 (the usual choice): ONE continuing controlled Dormand–Prince 5(4) run with dense
//    output. It takes its own steps (sized by its tolerance, not by the simulator's h), advances
//    only when the simulator passes its current step, and is read by interpolation at the instants
//    where it is compared (publish instants, output rows). At a command change it is read at that
//    instant and restarted there with the new command held, so the command takes effect at the
//    same scene time as in the simulation. Its trajectory depends only on the command-change
//    instants, never on how often it is compared.
//  - any other integrator: n = round(h / h_shadow) fixed sub-steps per simulator step (n ≥ 1).
// Work limits, refused at load (std::invalid_argument naming the key) or failing with a StepError
// that names them: tolerance ≥ kShadowToleranceFloor, n ≤ kMaxShadowSubsteps, at most
// kMaxShadowStepsPerStep dopri5 steps within one simulator step.
#pragma once

#include <cstdint>
#include <memory>

#include "birkhoff_cart/core/run/reference_solution.h"

namespace birkhoff_cart {

/// Smallest shadow dopri5 tolerance [-]: 100 ε. Below it the error test cannot pass in double
/// precision and the step size collapses (1e-24 took 10.7 s for 10 ms of scene time).
constexpr double kShadowToleranceFloor = 100.0 * 2.220446049250313e-16;
/// Most fixed-step shadow sub-steps per simulator step (h / h_shadow, rounded).
constexpr double kMaxShadowSubsteps = 1e4;
/// Most dopri5 steps the shadow may take within one simulator step.
constexpr std::uint64_t kMaxShadowStepsPerStep = 100000;

/// Builds the shadow reference for a simulation with step size `simulation_step` [s]. Throws
/// std::invalid_argument naming reference.integrator.* when the settings break a work limit.
std::unique_ptr<ReferenceSolution> make_shadow_reference(const IntegratorSettings& shadow, double simulation_step,
                                                         const CartState& initial, const CartModel& model,
                                                         const EffectSet& effects);

}  // namespace birkhoff_cart
