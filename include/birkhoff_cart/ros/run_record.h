// cart_sim's record (docs/ros_interface.md, "The bag"): one bag per run (the k-th ~reset starts the
// bag of run k + 1, run_bag_path()), written through a BagRecorder, and the first failure to write
// or close it, which stops the node (it does not run without its record). A write after a failure
// does nothing. Part of CartSimNode.
#pragma once

#include <cstdint>
#include <exception>
#include <memory>
#include <optional>
#include <string>

#include <ros/time.h>

#include "birkhoff_cart/ros/bag_recorder.h"

namespace birkhoff_cart {

class RunRecord {
 public:
  /// Opens the bag of run 1 at run_bag_path(`bag_path`, 1) (`compression`: none, lz4, bz2;
  /// `min_free_disk_space` [bytes]: refused below it). Throws BagRecorderError or
  /// std::invalid_argument naming the problem; warns when an earlier bag or a killed run's
  /// .active there was kept aside, and when another node records to `bag_path` (this node then
  /// records to own_bag_path() of it, and its later runs beside that).
  RunRecord(std::string bag_path, const std::string& compression, std::uint64_t min_free_disk_space);

  /// Queues one message at `stamp` while the record is unfailed; a failure is kept, not thrown.
  template <class M>
  void write(const std::string& topic, const ros::Time& stamp, const M& message) {
    if (failure_) return;
    try {
      bag_->write(topic, stamp, message);
    } catch (const std::exception& failure) {
      failure_ = failure.what();
    }
  }

  /// ~reset: closes this run's bag and opens the next run's (a failure is kept, "at ~reset: ...").
  void next_run();
  /// The end of the node: closes the bag (a failure to close follows the first failure).
  void finish();

  /// The first failure, or none.
  const std::optional<std::string>& failure() const { return failure_; }
  /// True once per bag, at its first publish instant: the world transform goes into each bag once.
  bool take_first_instant();
  /// The bag of the current run.
  const BagRecorder& bag() const { return *bag_; }
  /// Runs recorded so far, this one included.
  std::uint64_t run_index() const { return run_index_; }

 private:
  void open();

  std::string bag_path_;
  BagRecorder::Compression compression_;
  std::uint64_t min_free_disk_space_;  ///< [bytes]
  std::unique_ptr<BagRecorder> bag_;
  std::uint64_t run_index_ = 0;
  bool first_instant_taken_ = false;  ///< in the current bag
  std::optional<std::string> failure_;
};

}  // namespace birkhoff_cart
