#include "birkhoff_cart/core/run/run_summary.h"

#include <cmath>
#include <cstdio>
#include <cstring>

#include "birkhoff_cart/core/integrators/richardson_shadow.h"

namespace birkhoff_cart {

std::string local_error_estimate_summary(const StepStatistics& statistics, const std::string& integrator) {
  if (!has_local_error_estimate(statistics)) return "local error estimate: none (" + integrator + " has none)";
  char text[160];
  std::snprintf(text, sizeof text, "local error estimate: last %.3g, max %.3g, sum %.3g [-]",
                statistics.local_error_estimate_last_step, statistics.local_error_estimate_max,
                statistics.local_error_estimate_sum);
  return text;
}

std::string step_control_summary(const IntegratorSettings& settings, const StepStatistics& statistics) {
  if (settings.step_control == StepControl::kFixed) {
    if (statistics.rejected_steps == 0) return "";
    char text[200];
    std::snprintf(text, sizeof text, "fixed steps: %llu taken in substeps (h/2 ... h/64) where the whole step failed",
                  static_cast<unsigned long long>(statistics.rejected_steps));
    return text;
  }
  const char* control = to_string(settings.step_control);
  char text[448];
  if (statistics.internal_steps == 0) {
    std::snprintf(text, sizeof text, "%s step control: position tolerance %.3g m (no internal step yet)", control,
                  settings.position_tolerance);
  } else if (settings.step_control == StepControl::kReversible) {
    std::snprintf(text, sizeof text,
                  "reversible step control: position tolerance %.3g m, eps = %.4g rad, %llu internal steps "
                  "from %.3g s to %.3g s, %llu restarts with a smaller eps",
                  settings.position_tolerance, statistics.control_fictive_step,
                  static_cast<unsigned long long>(statistics.internal_steps), statistics.internal_step_min,
                  statistics.internal_step_max, static_cast<unsigned long long>(statistics.rejected_steps));
  } else {
    std::snprintf(text, sizeof text,
                  "adaptive step control: position tolerance %.3g m, %llu internal steps from %.3g s to %.3g s, "
                  "%llu rejected",
                  settings.position_tolerance, static_cast<unsigned long long>(statistics.internal_steps),
                  statistics.internal_step_min, statistics.internal_step_max,
                  static_cast<unsigned long long>(statistics.rejected_steps));
    if (std::isfinite(statistics.global_error_estimate)) {
      const std::size_t used = std::strlen(text);
      std::snprintf(text + used, sizeof text - used,
                    "; global error estimate %.2g m at t = %.6g s (Richardson shadow on %llu step pairs, %llu failed, "
                    "largest h*rho(J) %.2g: %s)",
                    statistics.global_error_estimate, statistics.global_error_estimate_time,
                    static_cast<unsigned long long>(statistics.global_error_paired_steps),
                    static_cast<unsigned long long>(statistics.global_error_failed_steps),
                    statistics.global_error_stiffness,
                    !global_error_estimate_in_range(statistics.global_error_paired_steps,
                                                    statistics.global_error_stiffness)
                        ? "beyond its range, it may under-state the error"
                    : statistics.global_error_estimate > settings.position_tolerance
                        ? "within its range, above the tolerance: ask a smaller one"
                        : "within its range");
    }
  }
  return text;
}

std::string actuator_summary(const Simulation& simulation) {
  const Simulation::ActuatorStatus status = simulation.actuator_status();
  std::string text;
  char part[200];
  if (status.steering_actuator) {
    std::snprintf(part, sizeof part, "steering motor applies %.6g N·m (input %.6g N·m)", status.steering_applied,
                  status.steering_input);
    text += part;
  }
  if (status.drive_actuator) {
    std::snprintf(part, sizeof part, "%sdrive motor applies %.6g N·m (input %.6g N·m)", text.empty() ? "" : "; ",
                  status.drive_applied, status.drive_input);
    text += part;
  }
  if (status.end_stops) {
    const double angle = simulation.scene().actuators.end_stops->angle;  // χ_s [rad]
    std::snprintf(part, sizeof part, "%send stops at +-%.6g rad: %s, end-stop events %llu", text.empty() ? "" : "; ", angle,
                  status.end_stop_contact > 0 ? "resting on the upper stop"
                  : status.end_stop_contact < 0 ? "resting on the lower stop"
                                                : "free",
                  static_cast<unsigned long long>(status.end_stop_events));
    text += part;
  }
  return text;
}

std::string run_summary(const Simulation& simulation, const AccuracyGuard& guard) {
  const StepStatistics& statistics = simulation.statistics();
  const Diagnostics diagnostics = simulation.diagnostics();
  char line[512];
  std::string text;
  std::snprintf(line, sizeof line,
                "summary: scene '%s', integrator %s, %s = %g s, t = %.9g s, %llu steps, %llu rhs evaluations\n",
                simulation.scene().name.c_str(), simulation.integrator_name().c_str(),
                simulation.scene().integrator.step_control != StepControl::kFixed ? "output step" : "h", simulation.step_size(),
                simulation.state().time, static_cast<unsigned long long>(statistics.steps),
                static_cast<unsigned long long>(statistics.rhs_evaluations));
  text += line;
  std::snprintf(line, sizeof line,
                "  energy balance residual %.3g J (%.3g of the largest T*), p2 balance residual %.3g kg·m²/s, "
                "max constraint residual %.3g m/s\n",
                diagnostics.energy_balance_residual, guard.current_value(AccuracyQuantity::kEnergyBalanceRelative),
                diagnostics.p2_balance_residual, diagnostics.max_constraint_residual);
  text += line;
  text += "  " + local_error_estimate_summary(statistics, simulation.integrator_name()) + "\n";
  const std::string control = step_control_summary(simulation.scene().integrator, statistics);
  if (!control.empty()) text += "  " + control + "\n";
  const std::string actuators = actuator_summary(simulation);
  if (!actuators.empty()) text += "  actuators: " + actuators + "\n";
  text += "  accuracy: " + guard.summary() + accuracy_binding_note(simulation, guard) + "\n";
  return text;
}

std::string accuracy_binding_note(const Simulation& simulation, const AccuracyGuard& guard) {
  const IntegratorSettings& settings = simulation.scene().integrator;
  if (settings.step_control == StepControl::kFixed || guard.level() != AccuracyLevel::kError) return "";
  char text[400];
  std::snprintf(text, sizeof text,
                " (under a step control the scene's accuracy limits judge every row, those between the member's "
                "steps from its dense output too, and may bind before position_tolerance %.3g m does: a smaller "
                "tolerance or looser limits in the scene's accuracy section)",
                settings.position_tolerance);
  return text;
}

}  // namespace birkhoff_cart
