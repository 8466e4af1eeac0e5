#include "birkhoff_cart/ros/accuracy_reporting.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include <diagnostic_msgs/DiagnosticStatus.h>

#include "birkhoff_cart/core/run_summary.h"

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
  const std::vector<AccuracyQuantity> quantities = {AccuracyQuantity::kEnergyBalanceRelative,
                                                    AccuracyQuantity::kP2Balance, AccuracyQuantity::kConstraint,
                                                    AccuracyQuantity::kEstimatedError};
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
