// cart_sim's pose requests (docs/ros_interface.md, "~set_state" and "initialpose"): the ~set_state
// service (pose, steering angle, speeds) and the initialpose topic (rviz's 2D Pose Estimate: the
// pose of a cart at rest). An initialpose may be in the odom frame or in any frame /tf_static fixes
// to it (cart_sim's own world frame, a world above several carts' world frames as in
// two_carts.launch): the static transforms are kept here as they are latched, and the pose is
// carried into odom. A request with an empty frame, a non-finite field, a degenerate quaternion or
// a frame not fixed to odom is refused by name here; a valid one becomes the target state of the
// node's teleport (a restart of the run there, Simulation::restart_from), which may still refuse it
// (a state no step resolves, a trial step that fails). Part of CartSimNode.
#pragma once

#include <functional>
#include <string>

#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <ros/ros.h>
#include <tf2/buffer_core.h>
#include <tf2_msgs/TFMessage.h>

#include "birkhoff_cart/SetCartState.h"
#include "birkhoff_cart/core/run/simulation.h"
#include "birkhoff_cart/ros/cart_sim_parameters.h"

namespace birkhoff_cart {

class PoseRequests {
 public:
  /// Restarts the run from `target`; false with `message` naming why not (nothing changed then).
  using Teleport = std::function<bool(const CartState& target, const std::string& source, std::string& message)>;

  /// Advertises ~set_state on `private_node`, subscribes to initialpose and /tf_static on `node`.
  PoseRequests(ros::NodeHandle& node, ros::NodeHandle& private_node, const CartSimParameters& parameters,
               const Simulation& simulation, Teleport teleport);

  /// The message of a teleport by `source` to `target` done at the simulation's time: base_link's
  /// position [m], heading, steering angle [rad], speeds; `recording`: the bag goes on.
  static std::string teleported(const std::string& source, const Simulation& simulation, const CartState& target,
                                bool recording);

 private:
  bool on_set_state(SetCartState::Request& request, SetCartState::Response& response);
  void on_initial_pose(const geometry_msgs::PoseWithCovarianceStamped::ConstPtr& message);
  void on_static_transforms(const tf2_msgs::TFMessage::ConstPtr& message);
  /// Logs the refusal of an initialpose: `why`, and that the run goes on unchanged.
  void refuse_initial_pose(const std::string& why) const;

  const CartSimParameters& parameters_;
  const Simulation& simulation_;
  Teleport teleport_;
  ros::ServiceServer set_state_service_;
  ros::Subscriber initial_pose_subscriber_;
  ros::Subscriber static_transform_subscriber_;
  tf2::BufferCore static_frames_;  ///< the transforms latched on /tf_static
};

}  // namespace birkhoff_cart
