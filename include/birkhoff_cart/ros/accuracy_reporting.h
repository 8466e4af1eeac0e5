// The accuracy guard in cart_sim (docs/accuracy.md §2): its limits from the scene's `accuracy`
// section overridden by the private parameters ~accuracy/<quantity>, and how its verdict and the
// local error estimate reach /diagnostics and the summary (~integration_error: InstantMessages). Translation only:
// AccuracyGuard (core) decides.
#pragma once

#include <string>

#include <diagnostic_updater/DiagnosticStatusWrapper.h>
#include <ros/node_handle.h>

#include "birkhoff_cart/core/scene/accuracy_guard.h"
#include "birkhoff_cart/core/integrators/diagnostics.h"

namespace birkhoff_cart {
namespace ros_accuracy {

/// `scene_requirements` with each ~accuracy/<quantity> parameter applied: the string "off", or a
/// map {warn: W, error: E} (0 < W ≤ E, finite); then the residual thresholds, each pair the limits
/// of one quantity: ~energy_residual_warn/error → energy_balance [J], ~p2_residual_warn/error →
/// p2_balance [kg·m²/s], ~constraint_residual_warn/error → constraint [m/s]. Throws
/// std::invalid_argument naming the parameter (also when a pair and ~accuracy/<its quantity> are both set).
AccuracyRequirements load_requirements(const ros::NodeHandle& private_node, const AccuracyRequirements& scene_requirements);

/// Raises `status` to the guard's worst level (WARN/ERROR) with its line appended to the message,
/// and adds the guard's and the estimate's key-values.
void report(diagnostic_updater::DiagnosticStatusWrapper& status, const AccuracyGuard& guard,
            const StepStatistics& statistics, const std::string& integrator);

/// " Accuracy: <guard summary>. <local error estimate line>." for the node's summary paragraph.
std::string summary_sentence(const AccuracyGuard& guard, const StepStatistics& statistics, const std::string& integrator);

}  // namespace ros_accuracy
}  // namespace birkhoff_cart
