// InstantPublisher (instant_publisher.h).
#include "birkhoff_cart/ros/instant_publisher.h"

#include "birkhoff_cart/IntegrationError.h"
#include "birkhoff_cart/ros/conversions.h"

namespace birkhoff_cart {

namespace {

/// Messages each subscriber's connection may hold per topic of an instant: a ~step call runs its
/// steps as fast as they go, so a burst of up to this many instants reaches a subscriber that drains
/// it a little later (with 50, a loaded machine's Python subscriber lost 8 of a 60-instant burst).
constexpr std::uint32_t kInstantQueue = 1000;

}  // namespace

InstantPublisher::InstantPublisher(ros::NodeHandle& node, ros::NodeHandle& private_node,
                                   const CartSimParameters& parameters, double start_time)
    : parameters_(parameters),
      odometry_(node, "odom", kInstantQueue),
      ground_truth_(node, "ground_truth", kInstantQueue),
      joints_(node, "joint_states", kInstantQueue),
      integration_error_(private_node, "integration_error", kInstantQueue),
      messages_(parameters.frames, parameters.odometry_covariance) {
  // /clock through a NodeHandle whose own remapping keeps it /clock: main() remaps roscpp's internal
  // /clock subscription of this process away (kUnheardClockTopic), so the node does not hear back
  // every /clock it publishes; it sets its own ROS time instead (publish_clock()).
  if (parameters_.publish_clock) {
    ros::NodeHandle clock_node(node, "", ros::M_string{{"/clock", "/clock"}});
    clock_ = Output<rosgraph_msgs::Clock>(clock_node, "/clock", 10);
  }
  // /tf through a publisher of our own rather than tf2_ros::TransformBroadcaster, whose
  // sendTransform() builds a new TFMessage (a vector) at every call; same topic and queue.
  ros::NodeHandle global;
  if (parameters_.publish_tf) transforms_ = Output<tf2_msgs::TFMessage>(global, "/tf", 100);
  // REP-105: the world frame (map) is the ground truth's; the odometry starts at the true pose, so
  // world → odom is the identity, latched on /tf_static once (docs/odometry_sensor.md, "Frames").
  world_transform_.transforms.push_back(ros_conversions::world_to_odom_transform(parameters_.frames, start_time));
  if (parameters_.publish_tf && parameters_.publish_world_tf) {
    static_transforms_ = Output<tf2_msgs::TFMessage>(global, "/tf_static", 10, true);
    static_transforms_.publish_always(world_transform_);
  }
}

void InstantPublisher::publish_clock(double time) {
  if (!parameters_.publish_clock) return;
  clock_message_.clock = ros_conversions::to_ros_time(time);
  clock_.publish(clock_message_);
  // This process does not hear its own /clock (main() remaps roscpp's subscription away): its ROS
  // time (log stamps, diagnostics) is set here instead.
  if (ros::Time::isSimTime()) ros::Time::setNow(clock_message_.clock);
}

bool InstantPublisher::listened() const {
  // An output not advertised (/clock, /tf switched off) is not heard.
  return odometry_.heard() || ground_truth_.heard() || joints_.heard() || integration_error_.heard() ||
         clock_.heard() || transforms_.heard();
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
  ground_truth_.publish_shared(messages_.ground_truth);
  odometry_.publish_shared(messages_.odometry);
  joints_.publish_shared(messages_.joints);
  integration_error_.publish(messages_.integration_error);
  // odom → base_link, once per stamp; also into the bag, so a replay in rviz places the cart.
  const ros::Time stamp = messages_.odometry.header.stamp;
  const bool transform_sent = parameters_.publish_tf && stamp != last_transform_stamp_;
  if (transform_sent) {
    transforms_.publish(messages_.transforms);
    last_transform_stamp_ = stamp;
  }
  if (!record) return;
  IntegrationError& error = messages_.integration_error;
  if (!parameters_.record_wall_time) error.wall_time_per_step = 0.0;  // the one field that differs between runs
  integration_error_.record(*record, error.header.stamp, error);
  // Once per bag, so that a replay has the world frame (also when ~publish_world_tf is off).
  if (record->take_first_instant()) record->write("/tf_static", stamp, world_transform_);
  // Without a sensor ground_truth equals odom (pose and twist): the bag keeps odom only.
  if (estimate) ground_truth_.record(*record, stamp, messages_.ground_truth);
  odometry_.record(*record, stamp, messages_.odometry);
  joints_.record(*record, messages_.joints.header.stamp, messages_.joints);
  if (transform_sent) record->write("/tf", stamp, messages_.transforms);
}

}  // namespace birkhoff_cart
