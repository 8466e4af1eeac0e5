// One output topic of cart_sim: its publisher, its resolved name (as the bag records it), publishing
// only when someone listens, and recording into the run's bag. A new topic is one member and one
// line where it is published. Part of CartSimNode (InstantPublisher).
#pragma once

#include <cstdint>
#include <string>

#include <boost/make_shared.hpp>
#include <ros/ros.h>

#include "birkhoff_cart/ros/run_record.h"

namespace birkhoff_cart {

template <class Message>
class Output {
 public:
  /// Not advertised: publishes nothing, heard() is false (a topic switched off, e.g. /clock).
  Output() = default;
  /// Advertises `name` on `node` with `queue_size` messages (`latch`: the last one kept for later
  /// subscribers).
  Output(ros::NodeHandle& node, const std::string& name, std::uint32_t queue_size, bool latch = false)
      : publisher_(node.advertise<Message>(name, queue_size, latch)), topic_(publisher_.getTopic()) {}

  /// The resolved name (kept: Publisher::getTopic() returns a copy at every call).
  const std::string& topic() const { return topic_; }
  /// Someone subscribes (0 for an output that was not advertised).
  bool heard() const { return publisher_.getNumSubscribers() > 0; }
  std::uint32_t subscribers() const { return publisher_.getNumSubscribers(); }

  /// Publishes `message` when someone subscribes. roscpp drops it without a subscriber anyway, but
  /// only after its typed publish() has built a std::string of the md5sum (an allocation) and looked
  /// the topic up under its global lock; the count is that look-up alone.
  void publish(const Message& message) const {
    if (heard()) publisher_.publish(message);
  }
  /// Publishes a shared copy of `message` when someone subscribes: a subscriber in the same process
  /// (a controller nodelet in cart_sim's manager) gets that copy without serialization; remote
  /// subscribers are served as by publish().
  void publish_shared(const Message& message) const {
    if (heard()) publisher_.publish(boost::make_shared<Message>(message));
  }
  /// Publishes `message` whoever listens (a latched output's one message).
  void publish_always(const Message& message) const { publisher_.publish(message); }
  /// Into the run's bag at `stamp`, under topic().
  void record(RunRecord& record, const ros::Time& stamp, const Message& message) const {
    record.write(topic_, stamp, message);
  }

 private:
  ros::Publisher publisher_;
  std::string topic_;
};

}  // namespace birkhoff_cart
