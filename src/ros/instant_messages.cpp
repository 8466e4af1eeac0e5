// The messages of one publish instant, filled in place (see instant_messages.h).
#include "birkhoff_cart/ros/instant_messages.h"

#include <utility>

namespace birkhoff_cart {
namespace {

/// The ground truth's covariances: it is the exact state.
const ros_conversions::OdometryCovariance kExactCovariance{{0, 0, 0, 0, 0, 0}, {0, 0, 0, 0, 0, 0}};

}  // namespace

InstantMessages::InstantMessages(ros_conversions::FrameNames frames, ros_conversions::OdometryCovariance covariance)
    : frames_(std::move(frames)), covariance_(covariance) {
  ground_truth_frames_ = frames_;
  ground_truth_frames_.odom = frames_.world;
  transforms.transforms.resize(1);
}

void InstantMessages::fill(const Simulation& simulation, const Diagnostics& diagnostics, const AccuracyGuard& guard,
                           double wall_time_per_step, const OdometryEstimate* estimate) {
  const CartState& state = simulation.state();
  const CartModel& model = simulation.model();
  ros_conversions::fill_odometry(ground_truth, state, model, ground_truth_frames_, kExactCovariance);
  if (estimate) {
    ros_conversions::fill_odometry(odometry, *estimate, frames_, covariance_);
    ros_conversions::fill_transform(transforms.transforms.front(), *estimate, frames_);
  } else {
    ros_conversions::fill_odometry(odometry, state, model, frames_, covariance_);
    ros_conversions::fill_transform(transforms.transforms.front(), state, model, frames_);
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
