// PoseRequests (pose_requests.h).
#include "birkhoff_cart/ros/pose_requests.h"

#include <cmath>
#include <sstream>
#include <utility>

#include <tf2/exceptions.h>
#include <tf2/utils.h>
#include <tf2_geometry_msgs/tf2_geometry_msgs.h>

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
  // Latched: every static transform published so far arrives once, then only new ones.
  static_transform_subscriber_ = node.subscribe("/tf_static", 100, &PoseRequests::on_static_transforms, this);
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

void PoseRequests::on_static_transforms(const tf2_msgs::TFMessage::ConstPtr& message) {
  for (const geometry_msgs::TransformStamped& transform : message->transforms) {
    static_frames_.setTransform(transform, "/tf_static", true);  // a malformed one is logged by tf2 and skipped
  }
}

void PoseRequests::refuse_initial_pose(const std::string& why) const {
  ROS_ERROR("cart_sim: %s refused: %s; the simulation goes on unchanged", initial_pose_subscriber_.getTopic().c_str(),
            why.c_str());
}

void PoseRequests::on_initial_pose(const geometry_msgs::PoseWithCovarianceStamped::ConstPtr& message) {
  const std::string& frame = message->header.frame_id;
  const std::string& odom = parameters_.frames.odom;
  if (frame.empty()) {
    refuse_initial_pose("header.frame_id is empty: name the frame of the pose ('" + odom +
                        "' or a frame /tf_static fixes to it, e.g. rviz's fixed frame)");
    return;
  }
  const geometry_msgs::Pose& pose = message->pose.pose;
  const std::pair<const char*, double> fields[] = {
      {"pose.pose.position.x", pose.position.x},       {"pose.pose.position.y", pose.position.y},
      {"pose.pose.position.z", pose.position.z},       {"pose.pose.orientation.x", pose.orientation.x},
      {"pose.pose.orientation.y", pose.orientation.y}, {"pose.pose.orientation.z", pose.orientation.z},
      {"pose.pose.orientation.w", pose.orientation.w}};
  for (const auto& [name, value] : fields) {
    if (!std::isfinite(value)) {
      std::ostringstream text;
      text << name << " must be finite, got " << value;
      refuse_initial_pose(text.str());
      return;
    }
  }
  const double norm = std::sqrt(pose.orientation.x * pose.orientation.x + pose.orientation.y * pose.orientation.y +
                                pose.orientation.z * pose.orientation.z + pose.orientation.w * pose.orientation.w);
  if (!(norm > 1e-6)) {
    std::ostringstream text;
    text << "the orientation quaternion pose.pose.orientation has norm " << norm;
    refuse_initial_pose(text.str());
    return;
  }
  // Into odom: directly (odom, or cart_sim's own world frame while ~publish_world_tf makes it the
  // identity), or through the static transforms from the pose's frame (a world above cart_sim's,
  // from a static_transform_publisher).
  geometry_msgs::Pose in_odom = pose;
  const bool world_is_odom = parameters_.publish_world_tf && frame == parameters_.frames.world;
  if (frame != odom && !world_is_odom) {
    try {
      const geometry_msgs::TransformStamped transform = static_frames_.lookupTransform(odom, frame, ros::Time(0));
      tf2::doTransform(pose, in_odom, transform);
    } catch (const tf2::TransformException& error) {
      refuse_initial_pose("the pose is in frame '" + frame + "', which /tf_static does not fix to '" + odom +
                          "' (cart_sim places the cart in '" + odom + "' or a frame fixed to it on /tf_static" +
                          (parameters_.publish_world_tf ? ", such as '" + parameters_.frames.world + "'" : "") +
                          "; set rviz's fixed frame to one): " + error.what());
      return;
    }
  }
  tf2::Quaternion orientation(in_odom.orientation.x, in_odom.orientation.y, in_odom.orientation.z,
                              in_odom.orientation.w);
  orientation.normalize();
  // Like rviz's 2D Pose Estimate on a robot at rest: the pose is set, the cart stands still, the
  // steering angle stays.
  CartState target = simulation_.state();
  place_hinge(target, in_odom.position.x, in_odom.position.y, tf2::getYaw(orientation),
              simulation_.model().parameters().wheelbase);
  target.forward_speed = 0.0;
  target.steering_rate = 0.0;
  std::string text;
  teleport_(target, initial_pose_subscriber_.getTopic(), text);
}

std::string PoseRequests::teleported(const std::string& source, const Simulation& simulation, const CartState& target,
                                     bool recording) {
  const Eigen::Vector2d base = simulation.model().rear_axle_midpoint(target);
  std::ostringstream text;
  text << source << ": teleported at t = " << format_seconds(simulation.state().time) << " s to base_link ("
       << base.x() << ", " << base.y() << ") m, heading " << target.heading << " rad, steering angle "
       << target.steering_angle << " rad, forward speed " << target.forward_speed << " m/s, steering rate "
       << target.steering_rate << " rad/s (a restart of the run from there" << (recording ? "; the bag goes on)" : ")");
  return text.str();
}

}  // namespace birkhoff_cart
