// cart_sim's pose requests (docs/ros_interface.md, "~set_state" and "initialpose"): the ~set_state
// service (pose, steering angle, speeds) and the initialpose topic (rviz's 2D Pose Estimate: the
// pose of a cart at rest, in odom, or in the world frame while map -> odom is cart_sim's identity).
// A request with a non-finite field, a degenerate quaternion or a foreign frame is refused by name
// here; a valid one becomes the target state of the node's teleport (a restart of the run there),
// which may still refuse it. Part of CartSimNode.
#pragma once

#include <functional>
#include <string>

#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <ros/ros.h>

#include "birkhoff_cart/SetCartState.h"
#include "birkhoff_cart/core/simulation.h"
#include "birkhoff_cart/ros/cart_sim_parameters.h"

namespace birkhoff_cart {

class PoseRequests {
 public:
  /// Restarts the run from `target`; false with `message` naming why not (nothing changed then).
  using Teleport = std::function<bool(const CartState& target, const std::string& source, std::string& message)>;

  /// Advertises ~set_state on `private_node` and subscribes to initialpose on `node`.
  PoseRequests(ros::NodeHandle& node, ros::NodeHandle& private_node, const CartSimParameters& parameters,
               const Simulation& simulation, Teleport teleport);

 private:
  bool on_set_state(SetCartState::Request& request, SetCartState::Response& response);
  void on_initial_pose(const geometry_msgs::PoseWithCovarianceStamped::ConstPtr& message);

  const CartSimParameters& parameters_;
  const Simulation& simulation_;
  Teleport teleport_;
  ros::ServiceServer set_state_service_;
  ros::Subscriber initial_pose_subscriber_;
};

}  // namespace birkhoff_cart
