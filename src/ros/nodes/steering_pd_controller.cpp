// steering_pd_controller: an example controller for cart_sim's lockstep mode (docs/ros_interface.md, "Node
// steering_pd_controller"). All the work is in SteeringPdController (also the nodelet
// birkhoff_cart/SteeringPdController).
// Exit codes: 0 shut down, 2 refused (bad parameter, name or remapping at start; a ~steering_joint
// that joint_states does not hold, within a second), 4 unexpected error.
#include <stdexcept>

#include <ros/ros.h>

#include "birkhoff_cart/core/support/version.h"
#include "birkhoff_cart/ros/node_main.h"
#include "birkhoff_cart/ros/steering_pd_controller.h"

int main(int argc, char** argv) {
  if (birkhoff_cart::print_version_if_asked(argc, argv, "steering_pd_controller")) return 0;
  return birkhoff_cart::run_node_main("steering_pd_controller", [&] {
    ros::init(argc, argv, "steering_pd_controller");
    ros::NodeHandle node;
    try {
      birkhoff_cart::SteeringPdController controller(node, ros::NodeHandle("~"));
      ros::spin();
      if (!controller.refusal().empty()) return birkhoff_cart::kNodeExitRefused;  // ~steering_joint not in joint_states
    } catch (const std::invalid_argument& error) {
      ROS_FATAL("steering_pd_controller: %s", error.what());
      return birkhoff_cart::kNodeExitRefused;
    }
    return 0;
  });
}
