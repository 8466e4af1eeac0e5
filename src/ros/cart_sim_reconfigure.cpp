// cart_sim's dynamic_reconfigure (cfg/CartSim.cfg, see cart_sim_node.h): the command limits and
// watchdog and the accuracy guard's limits change while the node runs; a bad set is refused by
// name and the running one kept. Served on the node's callback queue, so between steps (in
// lockstep, at a barrier).
#include "birkhoff_cart/ros/cart_sim_node.h"

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

CartSimConfig CartSimNode::reconfigure_config() const {
  CartSimConfig config;
  config.max_steering_torque = parameters_.max_steering_torque;
  config.max_drive_torque = parameters_.max_drive_torque;
  config.command_timeout = parameters_.command_timeout;
  const AccuracyRequirements& limits = accuracy_guard_.requirements();
  get_limit(limits.energy_balance_relative, config.energy_balance_relative_warn, config.energy_balance_relative_error);
  get_limit(limits.p2_balance, config.p2_balance_warn, config.p2_balance_error);
  get_limit(limits.constraint, config.constraint_warn, config.constraint_error);
  get_limit(limits.estimated_error, config.estimated_error_warn, config.estimated_error_error);
  get_limit(limits.energy_balance, config.energy_balance_warn, config.energy_balance_error);
  return config;
}

void CartSimNode::on_reconfigure(CartSimConfig& config, std::uint32_t /*level*/) {
  try {
    AccuracyRequirements limits = accuracy_guard_.requirements();
    set_limit(limits.energy_balance_relative, config.energy_balance_relative_warn, config.energy_balance_relative_error);
    set_limit(limits.p2_balance, config.p2_balance_warn, config.p2_balance_error);
    set_limit(limits.constraint, config.constraint_warn, config.constraint_error);
    set_limit(limits.estimated_error, config.estimated_error_warn, config.estimated_error_error);
    set_limit(limits.energy_balance, config.energy_balance_warn, config.energy_balance_error);
    validate(limits);  // names the quantity; nothing has changed yet
    commands_->set_limits(config.max_steering_torque, config.max_drive_torque, config.command_timeout);
    accuracy_guard_.set_requirements(limits);
    parameters_.max_steering_torque = config.max_steering_torque;
    parameters_.max_drive_torque = config.max_drive_torque;
    parameters_.command_timeout = config.command_timeout;
    ROS_INFO("cart_sim: reconfigured at t = %s s: max steering torque %g N m, max drive torque %g N m, command "
             "timeout %g s; accuracy limits from the next publish instant",
             format_seconds(simulation_->state().time).c_str(), config.max_steering_torque, config.max_drive_torque,
             config.command_timeout);
  } catch (const std::invalid_argument& error) {
    ROS_ERROR("cart_sim: reconfiguration refused (the running settings stay): %s", error.what());
    config = reconfigure_config();  // dynamic_reconfigure reports the settings in force
  }
}

}  // namespace birkhoff_cart
