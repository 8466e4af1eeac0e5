// cart_sim's publishing: /clock, the state at each publish instant, tf, the record (see cart_sim_node.h).
#include "birkhoff_cart/ros/cart_sim_node.h"

#include <rosgraph_msgs/Clock.h>
#include <tf2_msgs/TFMessage.h>

#include "birkhoff_cart/ros/accuracy_reporting.h"
#include "birkhoff_cart/ros/instant_schedule.h"

namespace birkhoff_cart {

void CartSimNode::publish_clock(double time) {
  if (!parameters_.publish_clock) return;
  rosgraph_msgs::Clock clock;
  clock.clock = ros_conversions::to_ros_time(time);
  clock_publisher_.publish(clock);
  // This process does not hear its own /clock (main() remaps roscpp's subscription away): its ROS
  // time (log stamps, diagnostics) is set here instead.
  if (ros::Time::isSimTime()) ros::Time::setNow(clock.clock);
}

void CartSimNode::publish_instant() {
  const CartState& state = simulation_->state();
  const CartModel& model = simulation_->model();
  const nav_msgs::Odometry odometry =
      ros_conversions::to_odometry(state, model, parameters_.frames, parameters_.odometry_covariance);
  const sensor_msgs::JointState joints = ros_conversions::to_joint_state(
      state, model, ros_conversions::actuator_efforts(*simulation_), parameters_.frames.joint_prefix);
  last_wall_time_per_step_ = period_steps_ > 0 ? period_stepping_wall_time_ / static_cast<double>(period_steps_) : 0.0;
  period_stepping_wall_time_ = 0.0;
  period_steps_ = 0;
  const Diagnostics diagnostics = simulation_->diagnostics();
  accuracy_guard_.check(state.time, diagnostics, simulation_->statistics());
  IntegrationError error = ros_conversions::to_integration_error(
      state, diagnostics, simulation_->statistics(), simulation_->integrator_name(), simulation_->step_size(),
      last_wall_time_per_step_);
  ros_accuracy::fill(error, accuracy_guard_);

  odometry_publisher_.publish(odometry);
  joint_state_publisher_.publish(joints);
  integration_error_publisher_.publish(error);
  // odom → base_link, once per stamp; also into the bag, so a replay in rviz places the cart.
  tf2_msgs::TFMessage transforms;
  if (parameters_.publish_tf && odometry.header.stamp != last_transform_stamp_) {
    transforms.transforms.push_back(ros_conversions::to_transform(state, model, parameters_.frames));
    transform_broadcaster_->sendTransform(transforms.transforms.front());
    last_transform_stamp_ = odometry.header.stamp;
  }
  ++published_instants_;
  if (recorder_ && !record_failure_) {
    if (!parameters_.record_wall_time) error.wall_time_per_step = 0.0;  // the one field that differs between runs
    try {
      recorder_->write(integration_error_publisher_.getTopic(), error.header.stamp, error);
      recorder_->write(odometry_publisher_.getTopic(), odometry.header.stamp, odometry);
      recorder_->write(joint_state_publisher_.getTopic(), joints.header.stamp, joints);
      if (!transforms.transforms.empty()) recorder_->write("/tf", odometry.header.stamp, transforms);
    } catch (const std::exception& failure) {
      record_failure_ = failure.what();
    }
  }
  if (pass_due_instants(simulation_->scene().initial_state.time, parameters_.diagnostic_period, state.time,
                        0.5 * simulation_->step_size(), next_diagnostic_index_)) {
    diagnostic_updater_->force_update();
  }
}

}  // namespace birkhoff_cart
