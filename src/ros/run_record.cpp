// RunRecord (run_record.h).
#include "birkhoff_cart/ros/run_record.h"

#include <utility>

#include <ros/console.h>

namespace birkhoff_cart {

RunRecord::RunRecord(std::string bag_path, const std::string& compression, std::uint64_t min_free_disk_space)
    : bag_path_(std::move(bag_path)),
      compression_(BagRecorder::parse_compression(compression)),
      min_free_disk_space_(min_free_disk_space) {
  open();
}

void RunRecord::open() {
  ++run_index_;
  first_instant_taken_ = false;
  bag_ = std::make_unique<BagRecorder>(run_bag_path(bag_path_, run_index_), compression_, min_free_disk_space_);
  if (!bag_->taken_path().empty()) {
    ROS_WARN("cart_sim: %s is being recorded by another running node (its .active file is locked): this run "
             "records to %s instead",
             bag_->taken_path().c_str(), bag_->path().c_str());
    // This node's later runs go beside its own first bag (<stem>_pid<pid>_run<k>.bag).
    if (run_index_ == 1) bag_path_ = bag_->path();
  }
  if (!bag_->crash_record_kept_as().empty()) {
    ROS_WARN("cart_sim: %s.active is the unfinished bag of a run that was killed: kept it as %s (`rosbag reindex "
             "%s` recovers its finished chunks)",
             bag_->path().c_str(), bag_->crash_record_kept_as().c_str(), bag_->crash_record_kept_as().c_str());
  }
  if (!bag_->earlier_bag_kept_as().empty()) {
    ROS_WARN("cart_sim: %s already held a bag: kept it as %s (a record never overwrites one)", bag_->path().c_str(),
             bag_->earlier_bag_kept_as().c_str());
  }
}

void RunRecord::next_run() {
  if (failure_) return;
  try {
    bag_->close();
    ROS_INFO("cart_sim: run %lu recorded to %s", static_cast<unsigned long>(run_index_), bag_->path().c_str());
    open();
  } catch (const std::exception& failure) {
    failure_ = std::string("at ~reset: ") + failure.what();
  }
}

void RunRecord::finish() {
  try {
    bag_->close();
  } catch (const std::exception& error) {
    // Keep the first cause (the failed write); the close failure follows it.
    failure_ = failure_ ? *failure_ + "; then " + error.what() : std::string(error.what());
  }
}

bool RunRecord::take_first_instant() {
  if (first_instant_taken_) return false;
  first_instant_taken_ = true;
  return true;
}

}  // namespace birkhoff_cart
