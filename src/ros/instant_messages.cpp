// The messages of one publish instant, filled in place (see instant_messages.h).
#include "birkhoff_cart/ros/instant_messages.h"

#include <utility>

namespace birkhoff_cart {
namespace {

/// The ground truth's covariances: it is the exact state.
const ros_conversions::OdometryCovariance kExactCovariance{{0, 0, 0, 0, 0, 0}, {0, 0, 0, 0, 0, 0}};

/// `to` gets `from`'s stamp, pose and twist: the same values fill_odometry computes from the same
/// state (A, the heading's quaternion, v_A and θ̇ cost sines and cosines), without computing them again.
void copy_motion(nav_msgs::Odometry& to, const nav_msgs::Odometry& from) {
  to.header.stamp = from.header.stamp;
  to.pose.pose = from.pose.pose;
  to.twist.twist = from.twist.twist;
}

/// The transform of `odometry`'s pose, between its frames, at its stamp.
void copy_pose(geometry_msgs::TransformStamped& transform, const nav_msgs::Odometry& odometry) {
  transform.header.stamp = odometry.header.stamp;
  transform.header.frame_id = odometry.header.frame_id;
  transform.child_frame_id = odometry.child_frame_id;
  transform.transform.translation.x = odometry.pose.pose.position.x;
  transform.transform.translation.y = odometry.pose.pose.position.y;
  transform.transform.translation.z = odometry.pose.pose.position.z;
  transform.transform.rotation = odometry.pose.pose.orientation;
}

}  // namespace

InstantMessages::InstantMessages(ros_conversions::FrameNames frames, ros_conversions::OdometryCovariance covariance)
    : frames_(std::move(frames)), covariance_(covariance) {
  ground_truth_frames_ = frames_;
  ground_truth_frames_.odom = frames_.world;
  ground_truth_frames_.base_link = frames_.ground_truth;
  transforms.transforms.resize(1);
  // What an instant never changes in the ground truth (the frames, the exact state's covariances 0).
  ground_truth.header.frame_id = ground_truth_frames_.odom;
  ground_truth.child_frame_id = ground_truth_frames_.base_link;
  ground_truth.pose.covariance.fill(0.0);
  ground_truth.twist.covariance.fill(0.0);
}

void InstantMessages::fill(const Simulation& simulation, const Diagnostics& diagnostics, const AccuracyGuard& guard,
                           double wall_time_per_step, const OdometryEstimate* estimate) {
  const CartState& state = simulation.state();
  const CartModel& model = simulation.model();
  if (estimate) {
    ros_conversions::fill_odometry(ground_truth, state, model, ground_truth_frames_, kExactCovariance);
    ros_conversions::fill_odometry(odometry, *estimate, frames_, covariance_);
    ros_conversions::fill_transform(transforms.transforms.front(), *estimate, frames_);
  } else {
    // One pose and twist of the exact state for all three messages.
    ros_conversions::fill_odometry(odometry, state, model, frames_, covariance_);
    copy_motion(ground_truth, odometry);
    copy_pose(transforms.transforms.front(), odometry);
  }
  ros_conversions::fill_joint_state(joints, state, model, ros_conversions::actuator_efforts(simulation),
                                    frames_.joint_prefix);
  ros_conversions::fill_integration_error(integration_error, state, diagnostics, simulation.statistics(),
                                          simulation.integrator_name(), simulation.step_size(), wall_time_per_step);
  integration_error.accuracy_level = static_cast<std::uint8_t>(guard.level());
  integration_error.accuracy_current_level = static_cast<std::uint8_t>(guard.current_level());
  // The worst-level line depends only on the guard's events: rebuilt (a new string) only when one
  // has been added.
  if (guard.events().size() != accuracy_events_seen_) {
    integration_error.accuracy_status = guard.summary();
    accuracy_events_seen_ = guard.events().size();
  }
}

}  // namespace birkhoff_cart
