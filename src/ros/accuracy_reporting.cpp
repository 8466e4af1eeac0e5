#include "birkhoff_cart/ros/accuracy_reporting.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <stdexcept>
#include <vector>

#include <diagnostic_msgs/DiagnosticStatus.h>

#include "birkhoff_cart/core/run/run_summary.h"
#include "birkhoff_cart/ros/parameter_reading.h"

namespace birkhoff_cart {
namespace ros_accuracy {
namespace {

double as_double(const XmlRpc::XmlRpcValue& value, const std::string& name) {
  if (value.getType() == XmlRpc::XmlRpcValue::TypeDouble) return static_cast<double>(XmlRpc::XmlRpcValue(value));
  if (value.getType() == XmlRpc::XmlRpcValue::TypeInt) return static_cast<int>(XmlRpc::XmlRpcValue(value));
  throw std::invalid_argument("parameter " + name + " must be a number");
}

unsigned char diagnostic_level(AccuracyLevel level) {
  switch (level) {
    case AccuracyLevel::kWarn: return diagnostic_msgs::DiagnosticStatus::WARN;
    case AccuracyLevel::kError: return diagnostic_msgs::DiagnosticStatus::ERROR;
    default: return diagnostic_msgs::DiagnosticStatus::OK;
  }
}

}  // namespace

AccuracyRequirements load_requirements(const ros::NodeHandle& private_node,
                                       const AccuracyRequirements& scene_requirements) {
  AccuracyRequirements requirements = scene_requirements;
  const std::vector<AccuracyQuantity> quantities(std::begin(kLimitedAccuracyQuantities),
                                                  std::end(kLimitedAccuracyQuantities));
  for (AccuracyQuantity quantity : quantities) {
    const std::string key = std::string("accuracy/") + to_string(quantity);
    const std::string name = private_node.resolveName(key);
    XmlRpc::XmlRpcValue value;
    if (!private_node.getParam(key, value)) continue;
    AccuracyLimit& limit = requirements.limit(quantity);
    if (value.getType() == XmlRpc::XmlRpcValue::TypeString && static_cast<std::string>(value) == "off") {
      limit.enabled = false;
      continue;
    }
    if (value.getType() != XmlRpc::XmlRpcValue::TypeStruct || !value.hasMember("warn") || !value.hasMember("error") ||
        value.size() != 2) {
      throw std::invalid_argument("parameter " + name + " must be 'off' or {warn: W, error: E}");
    }
    limit.enabled = true;
    limit.warn = as_double(value["warn"], name + "/warn");
    limit.error = as_double(value["error"], name + "/error");
    if (!(std::isfinite(limit.warn) && std::isfinite(limit.error) && limit.warn > 0.0 && limit.warn <= limit.error)) {
      throw std::invalid_argument("parameter " + name + " needs 0 < warn <= error, both finite");
    }
  }
  // cart_sim's residual thresholds, each pair one quantity's limits (docs/ros_interface.md): a pair
  // with either value set turns the quantity on, the unset one at its listed default.
  struct ResidualThresholds {
    const char* warn_name;
    const char* error_name;
    AccuracyQuantity quantity;
    double default_warn;   ///< [unit of the quantity]
    double default_error;  ///< [unit of the quantity]
  };
  static const ResidualThresholds kThresholds[] = {
      {"energy_residual_warn", "energy_residual_error", AccuracyQuantity::kEnergyBalance, 1e-4, 1e-1},
      {"p2_residual_warn", "p2_residual_error", AccuracyQuantity::kP2Balance, 1e-8, 1e-5},
      {"constraint_residual_warn", "constraint_residual_error", AccuracyQuantity::kConstraint, 1e-9, 1e-6},
  };
  for (const ResidualThresholds& thresholds : kThresholds) {
    const bool warn_set = private_node.hasParam(thresholds.warn_name);
    const bool error_set = private_node.hasParam(thresholds.error_name);
    if (!warn_set && !error_set) continue;
    const std::string key = std::string("accuracy/") + to_string(thresholds.quantity);
    const std::string pair = private_node.resolveName(warn_set ? thresholds.warn_name : thresholds.error_name);
    if (private_node.hasParam(key)) {
      throw std::invalid_argument("parameters " + pair + " and " + private_node.resolveName(key) +
                                  " both set the limits of " + to_string(thresholds.quantity) + "; keep one");
    }
    AccuracyLimit& limit = requirements.limit(thresholds.quantity);
    limit.enabled = true;
    limit.warn = read_double_parameter(private_node, thresholds.warn_name, thresholds.default_warn);
    limit.error = read_double_parameter(private_node, thresholds.error_name, thresholds.default_error);
    if (!(std::isfinite(limit.warn) && std::isfinite(limit.error) && limit.warn > 0.0 && limit.warn <= limit.error)) {
      throw std::invalid_argument("parameters " + private_node.resolveName(thresholds.warn_name) + " and " +
                                  private_node.resolveName(thresholds.error_name) +
                                  " need 0 < warn <= error, both finite (an unset one is " +
                                  (warn_set ? "error = " : "warn = ") +
                                  std::to_string(warn_set ? thresholds.default_error : thresholds.default_warn) + ")");
    }
  }
  return requirements;
}

void report(diagnostic_updater::DiagnosticStatusWrapper& status, const AccuracyGuard& guard,
            const StepStatistics& statistics, const std::string& integrator) {
  if (guard.level() != AccuracyLevel::kOk) {
    const unsigned char level = std::max(static_cast<unsigned char>(status.level), diagnostic_level(guard.level()));
    const std::string line = "accuracy " + guard.summary();
    const bool healthy = status.message.empty() || status.message == "integration healthy";
    status.summary(level, healthy ? line : status.message + "; " + line);
  }
  status.add("accuracy (worst)", guard.summary());
  status.add("accuracy (now)", guard.current_summary());
  status.add("local error estimate", local_error_estimate_summary(statistics, integrator));
}

std::string summary_sentence(const AccuracyGuard& guard, const StepStatistics& statistics,
                             const std::string& integrator) {
  return " Accuracy: " + guard.summary() + ". " + local_error_estimate_summary(statistics, integrator) + ".";
}

}  // namespace ros_accuracy
}  // namespace birkhoff_cart
