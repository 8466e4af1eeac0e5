// The node's own record: a compressed rosbag (format 2.0, BagFileWriter). While open the
// bag is "<path>.active" (like `rosbag record`); close() renames it to <path>, so a bag at <path>
// is always complete and readable by `rosbag info` and python rosbag.
//
// One file per recorder (BagFileClaim): "<path>.active" is created and locked for as long as the
// recorder writes it. A recorder that finds it locked by another (two launches on one master)
// records to "<stem>_pid<its process id>.bag" instead; an unlocked one (a killed run's) is kept
// aside under its time, like an earlier bag at <path>; a path that exists and is not a regular
// file is refused. Nothing another recorder writes is ever renamed, truncated or written over.
//
// Disk space: before opening, the recorder can refuse a directory with less free space than a
// minimum (cart_sim's ~min_free_disk_space), so a node never starts a record it cannot keep. A disk
// that fills during the run makes write() (or close()) throw; close() then closes what it can.
//
// Threading: serialization, compression and file calls (BagFileWriter) run on the recorder's own
// writer thread. write() copies the message into a bounded ring of reused slots (no allocation in
// steady state) and returns; the writer is woken once per kWakeBatch messages and writes all that
// are queued; when the ring is full write() waits for it (back pressure: no message is ever dropped). close() drains the ring, closes and renames the bag; the destructor
// does the same, so every exit path that unwinds the stack leaves a complete bag.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <variant>
#include <vector>

#include <nav_msgs/Odometry.h>
#include <ros/time.h>
#include <sensor_msgs/JointState.h>
#include <std_msgs/Float64.h>
#include <tf2_msgs/TFMessage.h>

#include "birkhoff_cart/CartEvent.h"
#include "birkhoff_cart/IntegrationError.h"
#include "birkhoff_cart/ros/bag_file_claim.h"
#include "birkhoff_cart/ros/bag_file_writer.h"

namespace birkhoff_cart {

/// The directory that holds `bag_path` ("." for a bare file name, "/" for a file at the root).
std::string bag_directory(const std::string& bag_path);

/// Where run `run` (1, 2, ...) of a node recording to `bag_path` goes: run 1 at `bag_path`, run
/// k > 1 (after k − 1 resets) at "<stem>_run<k>.bag" ("<path>_run<k>" without a .bag suffix).
std::string run_bag_path(const std::string& bag_path, std::uint64_t run);

/// The decision of the free-space check (pure): "" when `free_bytes` ≥ `min_free_bytes` or
/// `min_free_bytes` is 0 (check disabled); otherwise a message naming `directory`, the free bytes
/// and the required minimum [bytes].
std::string disk_space_shortage(const std::string& directory, std::uint64_t free_bytes,
                                std::uint64_t min_free_bytes);

/// Bytes an unprivileged writer may still use on the file system holding `directory`
/// (statvfs: f_bavail × f_frsize). Throws BagRecorderError naming the directory when statvfs fails.
std::uint64_t free_disk_space(const std::string& directory);

/// Where a recorder whose `bag_path` is taken by another running recorder records instead:
/// "<stem>_pid<process id>.bag" (k = 1), "<stem>_pid<process id>-<k>.bag" after (several
/// recorders of one process, nodelets in one manager). Keeps a path without ".bag" suffixless.
std::string own_bag_path(const std::string& bag_path, long process_id, int k);

class BagRecorder {
 public:
  enum class Compression { kNone, kLz4, kBz2 };
  /// The message types the node records (one slot of the ring holds any of them).
  using Message =
      std::variant<nav_msgs::Odometry, sensor_msgs::JointState, IntegrationError, std_msgs::Float64, tf2_msgs::TFMessage,
                   CartEvent>;
  /// Slots of the ring between the time loop and the writer thread [messages].
  static constexpr std::size_t kQueueCapacity = 1024;
  /// Messages queued before the waiting writer thread is woken (close() wakes it for the rest).
  static constexpr std::size_t kWakeBatch = 256;

  /// Claims "<path>.active" (BagFileClaim), opens it for writing and starts the writer thread.
  /// When another running recorder holds it, records to own_bag_path() instead (taken_path()
  /// says which path was taken). A file already at the path recorded to (an earlier run's bag) is
  /// never overwritten: it is first renamed to kept_path_for() of it, and earlier_bag_kept_as()
  /// says where; crash_record_kept_as() says where a killed run's "<path>.active" went. Throws
  /// BagRecorderError naming the path and the reason when it cannot record (empty path, a path
  /// that is a directory or another non-regular file, a missing or unwritable directory, ...) or,
  /// with `min_free_disk_space` > 0 [bytes], when the bag's directory has less free space than
  /// that (checked before anything is created or moved).
  BagRecorder(const std::string& path, Compression compression = Compression::kLz4,
              std::uint64_t min_free_disk_space = 0);
  /// Closes the bag (see close()); never throws.
  ~BagRecorder();
  BagRecorder(const BagRecorder&) = delete;
  BagRecorder& operator=(const BagRecorder&) = delete;

  /// Queues one message on `topic` at `time` (scene time; clamped to ROS's smallest bag time,
  /// 1 ns, so a command received at t = 0 is kept); waits while the ring is full. Throws
  /// BagRecorderError when an earlier write failed on the writer thread or the bag is closed.
  template <class M>
  void write(const std::string& topic, const ros::Time& time, const M& message) {
    std::unique_lock<std::mutex> lock(mutex_);
    if (queued_ == slots_.size() && !failure_ && open_) {
      // Full: wake the writer whatever the batch, and wait for it (back pressure, never a drop).
      loop_waiting_ = true;
      slot_filled_.notify_one();
      slot_free_.wait(lock, [this] { return queued_ < slots_.size() || failure_ || !open_; });
      loop_waiting_ = false;
    }
    throw_if_unusable();
    Slot& slot = slots_[(next_ + queued_) % slots_.size()];
    slot.topic = topic;  // reuses the slot's capacity
    slot.time = time < ros::TIME_MIN ? ros::TIME_MIN : time;
    if (M* held = std::get_if<M>(&slot.message)) {
      *held = message;
    } else {
      slot.message = message;
    }
    ++queued_;
    // The writer is woken once per kWakeBatch messages, not per message: a wake-up (futex, task
    // switch) cost more than writing the message itself.
    const bool wake = writer_waiting_ && queued_ >= kWakeBatch;
    lock.unlock();
    if (wake) slot_filled_.notify_one();
  }

  /// Drains the ring, flushes, closes and renames the bag to its final path. Idempotent. Throws
  /// BagRecorderError when a write failed or rosbag cannot finish the file (e.g. the disk is
  /// full): the bag then stays "<path>.active" with the chunks already on disk (`rosbag reindex`
  /// may recover them).
  void close();
  bool is_open() const { return open_; }

  /// The final path of the bag: the path asked for, or own_bag_path() of it when that was taken.
  const std::string& path() const { return path_; }
  /// The path asked for when another running recorder held it ("" otherwise).
  const std::string& taken_path() const { return taken_path_; }
  /// The path written while open.
  std::string active_path() const { return path_ + ".active"; }
  /// Where the bag is now: path() after a successful close(), active_path() otherwise (still
  /// open, or left unfinished by a failed close).
  std::string current_path() const { return finished_ ? path_ : active_path(); }
  /// Where the file found at path() when recording began went ("" when there was none).
  const std::string& earlier_bag_kept_as() const { return earlier_bag_kept_as_; }
  /// Where a killed run's unlocked "<path>.active" found when recording began went ("" when none).
  const std::string& crash_record_kept_as() const { return crash_record_kept_as_; }
  /// Messages written to the file per topic (complete after close()).
  std::map<std::string, std::uint64_t> message_counts() const;

  /// "lz4" → kLz4, "bz2" → kBz2, "none" → kNone; throws std::invalid_argument otherwise.
  static Compression parse_compression(const std::string& name);

 private:
  struct Slot {
    std::string topic;
    ros::Time time;
    Message message;
  };

  /// The writer thread: writes queued slots in order until closed and drained.
  void write_queued();
  /// Throws BagRecorderError for a failed writer or a closed bag (mutex_ held).
  void throw_if_unusable() const;
  /// " (N bytes free in DIR)" after a failed write, so the message says how full the disk is.
  /// "" when statvfs fails.
  std::string free_space_note() const;

  /// Keeps a regular file found at path_ under kept_path_for() (its name in earlier_bag_kept_as_).
  void keep_earlier_bag();

  std::string path_;
  std::string taken_path_;
  std::string earlier_bag_kept_as_;
  std::string crash_record_kept_as_;
  std::unique_ptr<BagFileClaim> claim_;  ///< "<path_>.active", locked until it is renamed to path_
  std::unique_ptr<BagFileWriter> bag_;
  bool open_ = false;      ///< accepting writes (mutex_)
  bool finished_ = false;  ///< closed and renamed to path_

  mutable std::mutex mutex_;
  std::condition_variable slot_free_;    ///< the writer freed a slot (or failed)
  std::condition_variable slot_filled_;  ///< the loop queued a slot (or closes)
  std::vector<Slot> slots_;
  std::size_t next_ = 0;    ///< the slot the writer takes next
  std::size_t queued_ = 0;  ///< filled slots not yet written
  bool writer_waiting_ = false;  ///< the writer sleeps on slot_filled_
  bool loop_waiting_ = false;    ///< write() sleeps on slot_free_ (ring full)
  std::optional<std::string> failure_;   ///< the writer's first failure
  std::map<std::string, std::uint64_t> message_counts_;
  // The writer thread's own (no lock): its first failure stops its writes; counts of its batch.
  bool failed_ = false;
  std::map<std::string, std::uint64_t> written_counts_;
  std::thread writer_;
};

}  // namespace birkhoff_cart
