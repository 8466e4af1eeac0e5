// RunSettings (run_settings.h).
#include "birkhoff_cart/ros/run_settings.h"

#include <stdexcept>

namespace birkhoff_cart {
namespace {

/// One quantity's limits as the cfg has them: warn and error both 0 = off.
void set_limit(AccuracyLimit& limit, double warn, double error) {
  limit.enabled = !(warn == 0.0 && error == 0.0);
  limit.warn = warn;
  limit.error = error;
}

void get_limit(const AccuracyLimit& limit, double& warn, double& error) {
  warn = limit.enabled ? limit.warn : 0.0;
  error = limit.enabled ? limit.error : 0.0;
}

}  // namespace

RunSettings::RunSettings(ros::NodeHandle& private_node, CartSimParameters& parameters, AccuracyGuard& guard,
                         CommandInputs& commands, const Simulation& simulation)
    : parameters_(parameters), guard_(guard), commands_(commands), simulation_(simulation),
      server_(mutex_, private_node) {
  // The settings in force first (not the cfg's defaults), then the callback.
  server_.updateConfig(in_force());
  server_.setCallback([this](CartSimConfig& config, std::uint32_t level) { on_reconfigure(config, level); });
  serving_ = true;
}

CartSimConfig RunSettings::in_force() const {
  CartSimConfig config;
  config.max_steering_torque = parameters_.max_steering_torque;
  config.max_drive_torque = parameters_.max_drive_torque;
  config.command_timeout = parameters_.command_timeout;
  const AccuracyRequirements& limits = guard_.requirements();
  get_limit(limits.energy_balance_relative, config.energy_balance_relative_warn, config.energy_balance_relative_error);
  get_limit(limits.p2_balance, config.p2_balance_warn, config.p2_balance_error);
  get_limit(limits.constraint, config.constraint_warn, config.constraint_error);
  get_limit(limits.estimated_error, config.estimated_error_warn, config.estimated_error_error);
  get_limit(limits.energy_balance, config.energy_balance_warn, config.energy_balance_error);
  return config;
}

void RunSettings::on_reconfigure(CartSimConfig& config, std::uint32_t /*level*/) {
  try {
    AccuracyRequirements limits = guard_.requirements();
    set_limit(limits.energy_balance_relative, config.energy_balance_relative_warn, config.energy_balance_relative_error);
    set_limit(limits.p2_balance, config.p2_balance_warn, config.p2_balance_error);
    set_limit(limits.constraint, config.constraint_warn, config.constraint_error);
    set_limit(limits.estimated_error, config.estimated_error_warn, config.estimated_error_error);
    set_limit(limits.energy_balance, config.energy_balance_warn, config.energy_balance_error);
    validate(limits);  // names the quantity; nothing has changed yet
    commands_.set_limits(config.max_steering_torque, config.max_drive_torque, config.command_timeout);
    guard_.set_requirements(limits);
    parameters_.max_steering_torque = config.max_steering_torque;
    parameters_.max_drive_torque = config.max_drive_torque;
    parameters_.command_timeout = config.command_timeout;
    if (!serving_) return;  // setCallback's own call with the settings in force: nothing to report
    ROS_INFO("cart_sim: reconfigured at t = %s s: max steering torque %g N m, max drive torque %g N m, command "
             "timeout %g s; accuracy limits from the next publish instant",
             format_seconds(simulation_.state().time).c_str(), config.max_steering_torque, config.max_drive_torque,
             config.command_timeout);
  } catch (const std::invalid_argument& error) {
    // The set answers with the settings in force (dynamic_reconfigure returns `config`), and the
    // line names the value typed (the cfg does not clamp: the node sees what was typed).
    ROS_WARN("cart_sim: dynamic_reconfigure set refused, the running settings stay: %s", error.what());
    config = in_force();
  }
}

}  // namespace birkhoff_cart
