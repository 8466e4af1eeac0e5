// PoseRequests (pose_requests.h).
#include "birkhoff_cart/ros/pose_requests.h"

#include <cmath>
#include <sstream>
#include <utility>

#include <tf2/utils.h>

namespace birkhoff_cart {
namespace {

/// The hinge B of a cart whose base_link (rear-axle midpoint A) is at (x, y) with heading θ:
/// B = A + l (cos θ, sin θ), the inverse of CartModel::rear_axle_midpoint (docs/model.md).
/// The heading is a new value: its compensated-summation low part (state.h) starts at 0.
void place_hinge(CartState& state, double base_x, double base_y, double heading, double wheelbase) {
  state.heading = heading;
  state.heading_low = 0.0;
  state.x = base_x + wheelbase * std::cos(heading);  // [m]
  state.y = base_y + wheelbase * std::sin(heading);  // [m]
}

}  // namespace

PoseRequests::PoseRequests(ros::NodeHandle& node, ros::NodeHandle& private_node, const CartSimParameters& parameters,
                           const Simulation& simulation, Teleport teleport)
    : parameters_(parameters), simulation_(simulation), teleport_(std::move(teleport)) {
  set_state_service_ = private_node.advertiseService("set_state", &PoseRequests::on_set_state, this);
  initial_pose_subscriber_ = node.subscribe("initialpose", 5, &PoseRequests::on_initial_pose, this);
}

bool PoseRequests::on_set_state(SetCartState::Request& request, SetCartState::Response& response) {
  const std::pair<const char*, double> fields[] = {
      {"x", request.x}, {"y", request.y}, {"heading", request.heading}, {"steering_angle", request.steering_angle},
      {"forward_speed", request.forward_speed}, {"steering_rate", request.steering_rate}};
  for (const auto& [name, value] : fields) {
    if (!std::isfinite(value)) {
      std::ostringstream text;
      text << "~set_state refused: " << name << " must be finite, got " << value << "; the simulation goes on unchanged";
      response.success = false;
      response.message = text.str();
      ROS_ERROR("cart_sim: %s", response.message.c_str());
      return true;
    }
  }
  CartState target = simulation_.state();  // keeps the time, the wheel spin angles and the arc length
  place_hinge(target, request.x, request.y, request.heading, simulation_.model().parameters().wheelbase);
  target.steering_angle = request.steering_angle;
  target.steering_angle_low = 0.0;
  target.forward_speed = request.forward_speed;
  target.steering_rate = request.steering_rate;
  response.success = teleport_(target, "~set_state", response.message);
  return true;
}

void PoseRequests::on_initial_pose(const geometry_msgs::PoseWithCovarianceStamped::ConstPtr& message) {
  // The odom frame, or the world frame while map -> odom is cart_sim's identity (~publish_world_tf):
  // the same coordinates. With a localizer of the user's owning map -> odom, only odom.
  const std::string& frame = message->header.frame_id;
  const bool world_is_odom = parameters_.publish_world_tf && frame == parameters_.frames.world;
  if (!frame.empty() && frame != parameters_.frames.odom && !world_is_odom) {
    ROS_ERROR("cart_sim: %s refused: the pose is in frame '%s', cart_sim places the cart in '%s'%s (set rviz's "
              "fixed frame to it); the simulation goes on unchanged",
              initial_pose_subscriber_.getTopic().c_str(), frame.c_str(), parameters_.frames.odom.c_str(),
              parameters_.publish_world_tf ? (" or '" + parameters_.frames.world + "'").c_str() : "");
    return;
  }
  const geometry_msgs::Pose& pose = message->pose.pose;
  const double values[] = {pose.position.x, pose.position.y, pose.orientation.x, pose.orientation.y,
                           pose.orientation.z, pose.orientation.w};
  for (double value : values) {
    if (!std::isfinite(value)) {
      ROS_ERROR("cart_sim: %s refused: a non-finite pose field (%g); the simulation goes on unchanged",
                initial_pose_subscriber_.getTopic().c_str(), value);
      return;
    }
  }
  const double norm = std::sqrt(pose.orientation.x * pose.orientation.x + pose.orientation.y * pose.orientation.y +
                                pose.orientation.z * pose.orientation.z + pose.orientation.w * pose.orientation.w);
  if (!(norm > 1e-6)) {
    ROS_ERROR("cart_sim: %s refused: the orientation quaternion has norm %g; the simulation goes on unchanged",
              initial_pose_subscriber_.getTopic().c_str(), norm);
    return;
  }
  tf2::Quaternion orientation(pose.orientation.x, pose.orientation.y, pose.orientation.z, pose.orientation.w);
  orientation.normalize();
  // Like rviz's 2D Pose Estimate on a robot at rest: the pose is set, the cart stands still, the
  // steering angle stays.
  CartState target = simulation_.state();
  place_hinge(target, pose.position.x, pose.position.y, tf2::getYaw(orientation),
              simulation_.model().parameters().wheelbase);
  target.forward_speed = 0.0;
  target.steering_rate = 0.0;
  std::string text;
  teleport_(target, initial_pose_subscriber_.getTopic(), text);
}

}  // namespace birkhoff_cart
