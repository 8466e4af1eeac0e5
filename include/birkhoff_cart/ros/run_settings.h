// What may change while cart_sim runs (docs/ros_interface.md, "While running"), through
// dynamic_reconfigure (cfg/CartSim.cfg): the command limits and watchdog timeout (CommandInputs)
// and the accuracy guard's limits (a quantity's warn and error both 0: off). A set that fails the
// checks is refused whole, by name, and the running settings stay. Served on the node's callback
// queue, so between steps (in lockstep, at a barrier). Part of CartSimNode.
#pragma once

#include <cstdint>

#include <boost/thread/recursive_mutex.hpp>
#include <dynamic_reconfigure/server.h>
#include <ros/ros.h>

#include "birkhoff_cart/CartSimConfig.h"
#include "birkhoff_cart/core/scene/accuracy_guard.h"
#include "birkhoff_cart/core/run/simulation.h"
#include "birkhoff_cart/ros/cart_sim_parameters.h"
#include "birkhoff_cart/ros/command_inputs.h"

namespace birkhoff_cart {

class RunSettings {
 public:
  /// Serves dynamic_reconfigure under `private_node`, starting from the settings in force.
  RunSettings(ros::NodeHandle& private_node, CartSimParameters& parameters, AccuracyGuard& guard,
              CommandInputs& commands, const Simulation& simulation);

  /// The settings dynamic_reconfigure may change, as they are in force.
  CartSimConfig in_force() const;

 private:
  void on_reconfigure(CartSimConfig& config, std::uint32_t level);

  CartSimParameters& parameters_;
  AccuracyGuard& guard_;
  CommandInputs& commands_;
  const Simulation& simulation_;
  boost::recursive_mutex mutex_;
  dynamic_reconfigure::Server<CartSimConfig> server_;
  bool serving_ = false;  ///< past the server's first call, which only repeats the settings in force
};

}  // namespace birkhoff_cart
