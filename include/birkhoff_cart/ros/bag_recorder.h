// The node's own record: a compressed rosbag written through the rosbag C++ API. While open the
// bag is "<path>.active" (like `rosbag record`); close() renames it to <path>, so a bag at <path>
// is always complete and readable by `rosbag info` and python rosbag.
//
// Disk space: before opening, the recorder can refuse a directory with less free space than a
// minimum (cart_sim's ~min_free_disk_space), so a node never starts a record it cannot keep. A disk
// that fills during the run makes write() throw; close() then closes what it can.
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

/// The directory that holds `bag_path` ("." for a bare file name, "/" for a file at the root).
std::string bag_directory(const std::string& bag_path);

/// The decision of the free-space check (pure): "" when `free_bytes` ≥ `min_free_bytes` or
/// `min_free_bytes` is 0 (check disabled); otherwise a message naming `directory`, the free bytes
/// and the required minimum [bytes].
std::string disk_space_shortage(const std::string& directory, std::uint64_t free_bytes,
                                std::uint64_t min_free_bytes);

/// Bytes an unprivileged writer may still use on the file system holding `directory`
/// (statvfs: f_bavail × f_frsize). Throws BagRecorderError naming the directory when statvfs fails.
std::uint64_t free_disk_space(const std::string& directory);

class BagRecorder {
 public:
  enum class Compression { kNone, kLz4, kBz2 };

  /// Opens "<path>.active" for writing. Throws BagRecorderError when it cannot (missing or
  /// unwritable directory, empty path, ...) or, with `min_free_disk_space` > 0 [bytes], when the
  /// bag's directory has less free space than that (checked before anything is created).
  BagRecorder(const std::string& path, Compression compression = Compression::kLz4,
              std::uint64_t min_free_disk_space = 0);
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
      throw BagRecorderError("cannot write " + topic + " to bag " + active_path() + ": " + error.what() +
                             free_space_note());
    }
    ++message_counts_[topic];
  }

  /// Flushes, closes and renames the bag to its final path. Idempotent. Throws BagRecorderError
  /// when rosbag cannot finish the file (e.g. the disk is full): the bag then stays
  /// "<path>.active" with the chunks already on disk (`rosbag reindex` may recover them).
  void close();
  bool is_open() const { return open_; }

  /// The final path of the bag (valid after close()).
  const std::string& path() const { return path_; }
  /// The path written while open.
  std::string active_path() const { return path_ + ".active"; }
  /// Where the bag is now: path() after a successful close(), active_path() otherwise (still
  /// open, or left unfinished by a failed close).
  std::string current_path() const { return finished_ ? path_ : active_path(); }
  /// Messages written per topic.
  const std::map<std::string, std::uint64_t>& message_counts() const { return message_counts_; }

  /// "lz4" → kLz4, "bz2" → kBz2, "none" → kNone; throws std::invalid_argument otherwise.
  static Compression parse_compression(const std::string& name);

 private:
  /// " (N bytes free in DIR)" after a failed write: rosbag's own messages ("Error seeking",
  /// "Problem writing data to disk") do not say that the disk is full. "" when statvfs fails.
  std::string free_space_note() const;

  std::string path_;
  std::unique_ptr<rosbag::Bag> bag_;
  bool open_ = false;
  bool finished_ = false;  ///< closed and renamed to path_
  std::map<std::string, std::uint64_t> message_counts_;
};

}  // namespace birkhoff_cart
