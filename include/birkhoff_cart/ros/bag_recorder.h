// The node's own record: a compressed rosbag written through the rosbag C++ API. While open the
// bag is "<path>.active" (like `rosbag record`); close() renames it to <path>, so a bag at <path>
// is always complete and readable by `rosbag info` and python rosbag.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>

#include <ros/time.h>
#include <rosbag/bag.h>

namespace birkhoff_cart {

/// The bag cannot be opened or written (the message names the path and the reason).
class BagRecorderError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class BagRecorder {
 public:
  enum class Compression { kNone, kLz4, kBz2 };

  /// Opens "<path>.active" for writing. Throws BagRecorderError when it cannot (missing or
  /// unwritable directory, empty path, ...).
  BagRecorder(const std::string& path, Compression compression = Compression::kLz4);
  /// Closes the bag (see close()); never throws.
  ~BagRecorder();
  BagRecorder(const BagRecorder&) = delete;
  BagRecorder& operator=(const BagRecorder&) = delete;

  /// Writes one message on `topic` at `time` (scene time; clamped to ROS's smallest bag time,
  /// 1 ns, so a command received at t = 0 is kept). Throws BagRecorderError on a write failure.
  template <class Message>
  void write(const std::string& topic, const ros::Time& time, const Message& message) {
    if (!open_) throw BagRecorderError("bag " + path_ + " is already closed");
    try {
      bag_->write(topic, time < ros::TIME_MIN ? ros::TIME_MIN : time, message);
    } catch (const std::exception& error) {
      throw BagRecorderError("cannot write " + topic + " to bag " + active_path() + ": " + error.what());
    }
    ++message_counts_[topic];
  }

  /// Flushes, closes and renames the bag to its final path. Idempotent.
  void close();
  bool is_open() const { return open_; }

  /// The final path of the bag (valid after close()).
  const std::string& path() const { return path_; }
  /// The path written while open.
  std::string active_path() const { return path_ + ".active"; }
  /// Messages written per topic.
  const std::map<std::string, std::uint64_t>& message_counts() const { return message_counts_; }

  /// "lz4" → kLz4, "bz2" → kBz2, "none" → kNone; throws std::invalid_argument otherwise.
  static Compression parse_compression(const std::string& name);

 private:
  std::string path_;
  std::unique_ptr<rosbag::Bag> bag_;
  bool open_ = false;
  std::map<std::string, std::uint64_t> message_counts_;
};

}  // namespace birkhoff_cart
