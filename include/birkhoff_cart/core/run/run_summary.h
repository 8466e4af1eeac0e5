// The end-of-run summary the batch CLI prints (and the node can log): work done, the balance
// residuals, the local error estimate and the accuracy guard's verdict (docs/accuracy.md).
#pragma once

#include <string>

#include "birkhoff_cart/core/scene/accuracy_guard.h"
#include "birkhoff_cart/core/run/simulation.h"

namespace birkhoff_cart {

/// "local error estimate: last 1.2e-09, max 3.4e-09, sum 5.6e-06 [-]" or "... none (<integrator> has none)".
std::string local_error_estimate_summary(const StepStatistics& statistics, const std::string& integrator);

/// One line on the step control (tolerance, ε, internal steps and their range); under step_control
/// "fixed", on the steps taken in substeps (StepStatistics::rejected_steps), empty when none.
std::string step_control_summary(const IntegratorSettings& settings, const StepStatistics& statistics);

/// One line on the actuators and end stops (docs/actuators.md): applied torques and inputs, the
/// contact and the number of events; empty when the scene has none.
std::string actuator_summary(const Simulation& simulation);

/// Several lines, each ending in '\n', each starting with two spaces except the first.
std::string run_summary(const Simulation& simulation, const AccuracyGuard& guard);

/// Under a step control, with the guard at ERROR: which binds — the scene's accuracy limits, which
/// judge every row, rows between the member's own steps included (its dense output), and can be
/// stricter than the position tolerance asked (docs/accuracy.md §4.4); empty otherwise.
std::string accuracy_binding_note(const Simulation& simulation, const AccuracyGuard& guard);

}  // namespace birkhoff_cart
