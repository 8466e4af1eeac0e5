// cart_sim: the simulator node (docs/ros_interface.md). All the work is in CartSimNode.
#include <ros/ros.h>

#include "birkhoff_cart/ros/cart_sim_node.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "cart_sim", ros::init_options::NoSigintHandler);
  birkhoff_cart::install_shutdown_signal_handlers();
  try {
    birkhoff_cart::CartSimNode node(ros::NodeHandle(), ros::NodeHandle("~"));
    const int exit_code = node.run();
    ros::shutdown();
    return exit_code;
  } catch (const birkhoff_cart::NodeStartupError& error) {
    ROS_FATAL("cart_sim: %s", error.what());
    return 2;
  }
}
