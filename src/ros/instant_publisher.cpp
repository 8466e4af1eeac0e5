// InstantPublisher (instant_publisher.h).
#include "birkhoff_cart/ros/instant_publisher.h"

#include <boost/make_shared.hpp>

#include "birkhoff_cart/IntegrationError.h"
#include "birkhoff_cart/ros/conversions.h"

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

/// Publishes `message` when someone subscribes. roscpp drops it without a subscriber anyway, but
/// only after its typed publish() has built a std::string of the md5sum (an allocation) and looked
/// the topic up under its global lock; the count is that look-up alone.
template <class Message>
void publish_if_heard(const ros::Publisher& publisher, const Message& message) {
  if (publisher.getNumSubscribers() > 0) publisher.publish(message);
}

}  // namespace

InstantPublisher::InstantPublisher(ros::NodeHandle& node, ros::NodeHandle& private_node,
                                   const CartSimParameters& parameters, double start_time)
    : parameters_(parameters), messages_(parameters.frames, parameters.odometry_covariance) {
  odometry_publisher_ = node.advertise<nav_msgs::Odometry>("odom", 50);
  ground_truth_publisher_ = node.advertise<nav_msgs::Odometry>("ground_truth", 50);
  joint_state_publisher_ = node.advertise<sensor_msgs::JointState>("joint_states", 50);
  integration_error_publisher_ = private_node.advertise<IntegrationError>("integration_error", 50);
  // /clock through a NodeHandle whose own remapping keeps it /clock: main() remaps roscpp's internal
  // /clock subscription of this process away (kUnheardClockTopic), so the node does not hear back
  // every /clock it publishes; it sets its own ROS time instead (publish_clock()).
  if (parameters_.publish_clock) {
    ros::NodeHandle clock_node(node, "", ros::M_string{{"/clock", "/clock"}});
    clock_publisher_ = clock_node.advertise<rosgraph_msgs::Clock>("/clock", 10);
  }
  // /tf through a publisher of our own rather than tf2_ros::TransformBroadcaster, whose
  // sendTransform() builds a new TFMessage (a vector) at every call; same topic and queue.
  if (parameters_.publish_tf) transform_publisher_ = ros::NodeHandle().advertise<tf2_msgs::TFMessage>(kTransformTopic, 100);
  odometry_topic_ = odometry_publisher_.getTopic();
  ground_truth_topic_ = ground_truth_publisher_.getTopic();
  // REP-105: the world frame (map) is the ground truth's; the odometry starts at the true pose, so
  // world → odom is the identity, latched on /tf_static once (docs/odometry_sensor.md, "Frames").
  world_transform_.transforms.push_back(ros_conversions::world_to_odom_transform(parameters_.frames, start_time));
  if (parameters_.publish_tf && parameters_.publish_world_tf) {
    static_transform_publisher_ = ros::NodeHandle().advertise<tf2_msgs::TFMessage>("/tf_static", 10, true);
    static_transform_publisher_.publish(world_transform_);
  }
  joint_state_topic_ = joint_state_publisher_.getTopic();
  integration_error_topic_ = integration_error_publisher_.getTopic();
}

void InstantPublisher::publish_clock(double time) {
  if (!parameters_.publish_clock) return;
  clock_message_.clock = ros_conversions::to_ros_time(time);
  publish_if_heard(clock_publisher_, clock_message_);
  // This process does not hear its own /clock (main() remaps roscpp's subscription away): its ROS
  // time (log stamps, diagnostics) is set here instead.
  if (ros::Time::isSimTime()) ros::Time::setNow(clock_message_.clock);
}

bool InstantPublisher::listened() const {
  // An unadvertised publisher (/clock, /tf switched off) counts 0.
  for (const ros::Publisher* publisher : {&odometry_publisher_, &ground_truth_publisher_, &joint_state_publisher_,
                                          &integration_error_publisher_, &clock_publisher_, &transform_publisher_}) {
    if (publisher->getNumSubscribers() > 0) return true;
  }
  return false;
}

void InstantPublisher::publish(const Simulation& simulation, const Diagnostics& diagnostics,
                               const AccuracyGuard& guard, double wall_time_per_step,
                               const OdometryEstimate* estimate, RunRecord* record) {
  // The messages are members filled in place (InstantMessages): nothing is allocated here once
  // they hold their strings. A topic without subscribers is not handed to roscpp at all: its typed
  // publish() builds a std::string of the md5sum at every call (ros/publisher.h), and serializes
  // into a buffer of its own for a topic with subscribers.
  messages_.fill(simulation, diagnostics, guard, wall_time_per_step, estimate);
  // The controllers' inputs as shared messages (zero-copy in a nodelet manager).
  publish_shared(ground_truth_publisher_, messages_.ground_truth);
  publish_shared(odometry_publisher_, messages_.odometry);
  publish_shared(joint_state_publisher_, messages_.joints);
  publish_if_heard(integration_error_publisher_, messages_.integration_error);
  // odom → base_link, once per stamp; also into the bag, so a replay in rviz places the cart.
  const ros::Time stamp = messages_.odometry.header.stamp;
  const bool transform_sent = parameters_.publish_tf && stamp != last_transform_stamp_;
  if (transform_sent) {
    publish_if_heard(transform_publisher_, messages_.transforms);
    last_transform_stamp_ = stamp;
  }
  if (!record) return;
  IntegrationError& error = messages_.integration_error;
  if (!parameters_.record_wall_time) error.wall_time_per_step = 0.0;  // the one field that differs between runs
  record->write(integration_error_topic_, error.header.stamp, error);
  // Once per bag, so that a replay has the world frame.
  if (record->take_first_instant()) record->write("/tf_static", stamp, world_transform_);
  // Without a sensor ground_truth equals odom (pose and twist): the bag keeps odom only.
  if (estimate) record->write(ground_truth_topic_, stamp, messages_.ground_truth);
  record->write(odometry_topic_, stamp, messages_.odometry);
  record->write(joint_state_topic_, messages_.joints.header.stamp, messages_.joints);
  if (transform_sent) record->write(kTransformTopic, stamp, messages_.transforms);
}

}  // namespace birkhoff_cart
