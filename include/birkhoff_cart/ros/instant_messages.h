// The messages cart_sim publishes and records at one publish instant, kept as members and filled
// in place from the simulation: once they have held their strings (frame and joint names, the
// integrator's name, the accuracy status) a publish instant allocates nothing here
// (instant_messages_test counts the allocations of steps, fills and bag writes). ROS-free of any
// master: publishing is InstantPublisher's (instant_publisher.h).
#pragma once

#include <cstddef>
#include <limits>

#include <nav_msgs/Odometry.h>
#include <rosgraph_msgs/Clock.h>
#include <sensor_msgs/JointState.h>
#include <tf2_msgs/TFMessage.h>

#include "birkhoff_cart/IntegrationError.h"
#include "birkhoff_cart/core/scene/accuracy_guard.h"
#include "birkhoff_cart/core/run/simulation.h"
#include "birkhoff_cart/ros/conversions.h"

namespace birkhoff_cart {

class InstantMessages {
 public:
  InstantMessages(ros_conversions::FrameNames frames, ros_conversions::OdometryCovariance covariance);

  /// Fills ground_truth, odometry, joints, the odom → base_link transform and integration_error
  /// from the simulation's current state and its `diagnostics` (simulation.diagnostics(), computed
  /// once by the caller); the accuracy fields of integration_error are read from `guard`, which the
  /// caller has checked with the same diagnostics (a fill changes nothing but the messages).
  /// `wall_time_per_step` [s] goes into integration_error. With an odometry sensor's `estimate`,
  /// odometry and the transform are the estimate's; without, they are the exact state, as
  /// ground_truth is.
  void fill(const Simulation& simulation, const Diagnostics& diagnostics, const AccuracyGuard& guard,
            double wall_time_per_step, const OdometryEstimate* estimate = nullptr);

  nav_msgs::Odometry ground_truth;  ///< the exact state: base_link in the world frame, covariances 0
  nav_msgs::Odometry odometry;      ///< in odom: the exact state, or the odometry sensor's estimate
  sensor_msgs::JointState joints;
  tf2_msgs::TFMessage transforms;  ///< one transform: odom → base_link
  IntegrationError integration_error;

 private:
  ros_conversions::FrameNames frames_;
  ros_conversions::FrameNames ground_truth_frames_;  ///< frames_ with the world frame as the fixed one
  ros_conversions::OdometryCovariance covariance_;
  /// The guard's event count when its status line was last written (it changes only with them).
  std::size_t accuracy_events_seen_ = std::numeric_limits<std::size_t>::max();
};

}  // namespace birkhoff_cart
