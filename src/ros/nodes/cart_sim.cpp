// cart_sim: the simulator node (README.md, "ROS interface"). All the work is in CartSimNode.
#include <ros/ros.h>

#include "birkhoff_cart/core/version.h"
#include "birkhoff_cart/ros/cart_sim_node.h"

int main(int argc, char** argv) {
  if (birkhoff_cart::print_version_if_asked(argc, argv, "cart_sim")) return 0;
  ros::init(argc, argv, "cart_sim", ros::init_options::NoSigintHandler);
  birkhoff_cart::install_shutdown_signal_handlers();
  // Outlives the node: when the last NodeHandle dies roscpp shuts down and drops later log output,
  // so the FATAL message below would be lost.
  ros::NodeHandle node_handle;
  try {
    birkhoff_cart::CartSimNode node(node_handle, ros::NodeHandle("~"));
    return node.run();
  } catch (const birkhoff_cart::NodeStartupError& error) {
    ROS_FATAL("cart_sim: %s", error.what());
    return birkhoff_cart::CartSimNode::kExitStartupFailure;
  }
}
