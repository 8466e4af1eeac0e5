// cmd_vel_controller: drives cart_sim from geometry_msgs/Twist on cmd_vel (docs/ros_interface.md, "Node
// cmd_vel_controller"). All the work is in CmdVelControllerNode and CmdVelController.
// Exit codes: 0 shut down, 2 refused (a bad parameter, name or remapping at start; ~steering_joint
// not in joint_states within a second of the first), 4 unexpected error.
#include <ros/ros.h>

#include "birkhoff_cart/core/support/version.h"
#include "birkhoff_cart/ros/cmd_vel_controller_node.h"
#include "birkhoff_cart/ros/node_main.h"

int main(int argc, char** argv) {
  if (birkhoff_cart::print_version_if_asked(argc, argv, "cmd_vel_controller")) return 0;
  return birkhoff_cart::run_node_main("cmd_vel_controller", [&] {
    ros::init(argc, argv, "cmd_vel_controller");
    ros::NodeHandle node_handle;
    try {
      birkhoff_cart::CmdVelControllerNode node(node_handle, ros::NodeHandle("~"));
      ros::spin();
      if (!node.refusal().empty()) return birkhoff_cart::kNodeExitRefused;  // ~steering_joint not in joint_states
    } catch (const std::invalid_argument& error) {
      ROS_FATAL("cmd_vel_controller: bad parameter: %s", error.what());
      return birkhoff_cart::kNodeExitRefused;
    }
    return 0;
  });
}
