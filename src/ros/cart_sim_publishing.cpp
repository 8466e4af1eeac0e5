// cart_sim's publishing: /clock, the state at each publish instant, tf, the record (see cart_sim_node.h).
#include "birkhoff_cart/ros/cart_sim_node.h"

#include "birkhoff_cart/ros/instant_schedule.h"

#include <boost/make_shared.hpp>

namespace birkhoff_cart {
namespace {

/// Publishes a shared copy of `message`: a subscriber in the same process (a controller nodelet in
/// cart_sim's manager) gets that copy without serialization; remote subscribers are served as by
/// publish(message). Nothing when no one subscribes.
template <class Message>
void publish_shared(const ros::Publisher& publisher, const Message& message) {
  if (publisher.getNumSubscribers() == 0) return;
  publisher.publish(boost::make_shared<Message>(message));
}

}  // namespace

void CartSimNode::publish_clock(double time) {
  if (!parameters_.publish_clock) return;
  clock_message_.clock = ros_conversions::to_ros_time(time);
  clock_publisher_.publish(clock_message_);
  // This process does not hear its own /clock (main() remaps roscpp's subscription away): its ROS
  // time (log stamps, diagnostics) is set here instead.
  if (ros::Time::isSimTime()) ros::Time::setNow(clock_message_.clock);
}

void CartSimNode::publish_instant() {
  // The messages are members filled in place (InstantMessages): the node allocates nothing here
  // once they hold their strings. roscpp 1.15's typed publish() still builds a std::string of the
  // md5sum at every call (ros/publisher.h), and serializes into a buffer of its own for a topic
  // with subscribers.
  const double wall_time_per_step = work_.end_period();  // [s]
  InstantMessages& messages = *instant_messages_;
  const OdometryEstimate* estimate = odometry_sensor_ ? &odometry_sensor_->read(simulation_->state()) : nullptr;
  // The accuracy guard is judged here, once per instant, before the messages are filled from it.
  const Diagnostics diagnostics = simulation_->diagnostics();
  accuracy_guard_.check(simulation_->state().time, diagnostics, simulation_->statistics());
  messages.fill(*simulation_, diagnostics, accuracy_guard_, wall_time_per_step, estimate);

  // The controllers' inputs as shared messages (zero-copy in a nodelet manager).
  publish_shared(ground_truth_publisher_, messages.ground_truth);
  publish_shared(odometry_publisher_, messages.odometry);
  publish_shared(joint_state_publisher_, messages.joints);
  integration_error_publisher_.publish(messages.integration_error);
  // odom → base_link, once per stamp; also into the bag, so a replay in rviz places the cart.
  const ros::Time stamp = messages.odometry.header.stamp;
  const bool transform_sent = parameters_.publish_tf && stamp != last_transform_stamp_;
  if (transform_sent) {
    transform_publisher_.publish(messages.transforms);
    last_transform_stamp_ = stamp;
  }
  if (record_) {
    IntegrationError& error = messages.integration_error;
    if (!parameters_.record_wall_time) error.wall_time_per_step = 0.0;  // the one field that differs between runs
    record_->write(integration_error_topic_, error.header.stamp, error);
    // Once per bag, so that a replay has the world frame.
    if (record_->take_first_instant()) record_->write("/tf_static", stamp, world_transform_);
    // Without a sensor ground_truth equals odom (pose and twist): the bag keeps odom only.
    if (odometry_sensor_) record_->write(ground_truth_topic_, stamp, messages.ground_truth);
    record_->write(odometry_topic_, stamp, messages.odometry);
    record_->write(joint_state_topic_, messages.joints.header.stamp, messages.joints);
    if (transform_sent) record_->write(kTransformTopic, stamp, messages.transforms);
  }
  if (pass_due_instants(simulation_->scene().initial_state.time, parameters_.diagnostic_period, simulation_->state().time,
                        0.5 * simulation_->step_size(), next_diagnostic_index_)) {
    diagnostic_updater_->force_update();
  }
}

}  // namespace birkhoff_cart
