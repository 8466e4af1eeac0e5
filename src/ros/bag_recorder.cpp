// The node's compressed rosbag record (see bag_recorder.h).
#include "birkhoff_cart/ros/bag_recorder.h"

#include <sys/stat.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>

namespace birkhoff_cart {
namespace {

// Recorders of one process that may find their path taken, one after the other (nodelets in one
// manager): a bound on the own paths tried.
constexpr int kMostOwnPaths = 100;

}  // namespace

std::string bag_directory(const std::string& bag_path) {
  const std::size_t slash = bag_path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  if (slash == 0) return "/";
  return bag_path.substr(0, slash);
}

std::string run_bag_path(const std::string& bag_path, std::uint64_t run) {
  if (run <= 1) return bag_path;
  const std::string stem = bag_stem(bag_path);
  return stem + "_run" + std::to_string(run) + (stem != bag_path ? ".bag" : "");
}

std::string own_bag_path(const std::string& bag_path, long process_id, int k) {
  const std::string stem = bag_stem(bag_path);
  return stem + "_pid" + std::to_string(process_id) + (k > 1 ? "-" + std::to_string(k) : std::string()) +
         (stem != bag_path ? ".bag" : "");
}

std::string disk_space_shortage(const std::string& directory, std::uint64_t free_bytes,
                                std::uint64_t min_free_bytes) {
  if (min_free_bytes == 0 || free_bytes >= min_free_bytes) return "";
  return "only " + std::to_string(free_bytes) + " bytes free in " + directory + ", below the required minimum of " +
         std::to_string(min_free_bytes) + " bytes (~min_free_disk_space; 0 disables the check)";
}

std::uint64_t free_disk_space(const std::string& directory) {
  struct statvfs info;
  if (::statvfs(directory.c_str(), &info) != 0) {
    throw BagRecorderError("cannot read the free space of " + directory + ": " + std::strerror(errno));
  }
  return static_cast<std::uint64_t>(info.f_bavail) * static_cast<std::uint64_t>(info.f_frsize);
}

BagRecorder::BagRecorder(const std::string& path, Compression compression, std::uint64_t min_free_disk_space)
    : path_(path), slots_(kQueueCapacity) {
  if (path.empty()) throw BagRecorderError("bag path is empty");
  if (min_free_disk_space > 0) {
    const std::string directory = bag_directory(path);
    std::uint64_t free_bytes = 0;
    try {
      free_bytes = free_disk_space(directory);
    } catch (const BagRecorderError& error) {
      throw BagRecorderError("cannot record to " + path + ": " + error.what());
    }
    const std::string shortage = disk_space_shortage(directory, free_bytes, min_free_disk_space);
    if (!shortage.empty()) throw BagRecorderError("cannot record to " + path + ": " + shortage);
  }
  // The claim first: what is at the path is looked at (and an earlier bag moved) only by the
  // recorder that holds "<path>.active", so no two recorders ever handle one file.
  for (int k = 1; !claim_; ++k) {
    const std::string kind = non_regular_file_kind(path_);
    if (!kind.empty()) {
      throw BagRecorderError("cannot record to " + path_ + ": it is " + kind +
                             ", not a bag file (it is left as it is; ~bag_path names the bag file itself)");
    }
    claim_ = BagFileClaim::claim(path_, crash_record_kept_as_);
    if (claim_) break;
    if (k == kMostOwnPaths) {
      throw BagRecorderError("cannot record to " + taken_path_ + ": it and " + std::to_string(k - 1) +
                             " other names are being recorded by running recorders");
    }
    if (taken_path_.empty()) taken_path_ = path;
    path_ = own_bag_path(path, static_cast<long>(::getpid()), k);
  }
  BagFileWriter::Compression file_compression = BagFileWriter::Compression::kLz4;
  switch (compression) {
    case Compression::kNone: file_compression = BagFileWriter::Compression::kNone; break;
    case Compression::kLz4: file_compression = BagFileWriter::Compression::kLz4; break;
    case Compression::kBz2: file_compression = BagFileWriter::Compression::kBz2; break;
  }
  try {
    keep_earlier_bag();
    try {
      bag_ = std::make_unique<BagFileWriter>(claim_->descriptor(), active_path(), file_compression);
    } catch (const BagFileError& error) {
      throw BagRecorderError("cannot open bag " + active_path() + " for writing: " + error.what());
    }
  } catch (...) {
    ::unlink(active_path().c_str());  // the claimed file is this recorder's own, and holds nothing yet
    throw;
  }
  open_ = true;
  writer_ = std::thread(&BagRecorder::write_queued, this);
}

BagRecorder::~BagRecorder() {
  try {
    close();
  } catch (...) {
    // A destructor must not throw; close() already reported what it could.
  }
}

void BagRecorder::throw_if_unusable() const {
  if (failure_) throw BagRecorderError(*failure_);
  if (!open_) throw BagRecorderError("bag " + path_ + " is already closed");
}

void BagRecorder::write_queued() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (true) {
    writer_waiting_ = true;
    slot_filled_.wait(lock, [this] { return queued_ >= kWakeBatch || (loop_waiting_ && queued_ > 0) || !open_; });
    writer_waiting_ = false;
    if (queued_ == 0) return;  // closed and drained (woken with nothing queued only by close())
    // The queued slots are the writer's until released below: the loop fills only free slots.
    const std::size_t batch = queued_;
    const std::size_t first = next_;
    lock.unlock();
    std::optional<std::string> failed;
    for (std::size_t k = 0; k < batch && !failed && !failed_; ++k) {
      Slot& slot = slots_[(first + k) % slots_.size()];
      try {
        std::visit([&](const auto& message) { bag_->write(slot.topic, slot.time, message); }, slot.message);
      } catch (const std::exception& error) {
        failed = "cannot write " + slot.topic + " to bag " + active_path() + ": " + error.what() + free_space_note();
      }
      if (!failed) ++written_counts_[slot.topic];
    }
    lock.lock();
    if (failed && !failure_) {
      failure_ = failed;
      failed_ = true;
    }
    for (auto& [topic, count] : written_counts_) {
      message_counts_[topic] += count;
      count = 0;
    }
    next_ = (next_ + batch) % slots_.size();  // a failed batch's rest is dropped: the record has failed
    queued_ -= batch;
    if (loop_waiting_ || failure_) slot_free_.notify_all();
  }
}

std::map<std::string, std::uint64_t> BagRecorder::message_counts() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return message_counts_;
}

void BagRecorder::close() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!open_) return;
    open_ = false;
  }
  slot_filled_.notify_all();
  slot_free_.notify_all();
  if (writer_.joinable()) writer_.join();  // the writer drains the ring first
  try {
    bag_->close();
  } catch (const std::exception& error) {
    // The chunks already written stay in "<path>.active" (unindexed) for `rosbag reindex`.
    throw BagRecorderError("cannot close bag " + active_path() + " (left as it is): " + error.what() +
                           (failure_ ? " (after: " + *failure_ + ")" : std::string()));
  }
  if (failure_) throw BagRecorderError(*failure_ + " (bag closed with the messages written before)");
  // Never over a file: one put at the path while recording (by a program that does not claim
  // paths) is kept aside as an earlier bag would have been.
  if (::access(path_.c_str(), F_OK) == 0) keep_earlier_bag();
  if (std::rename(active_path().c_str(), path_.c_str()) != 0) {
    throw BagRecorderError("cannot rename " + active_path() + " to " + path_ + ": " + std::strerror(errno));
  }
  finished_ = true;
  claim_.reset();  // renamed: the lock is no longer needed
}

void BagRecorder::keep_earlier_bag() {
  if (::access(path_.c_str(), F_OK) != 0) return;
  const std::string kind = non_regular_file_kind(path_);
  if (!kind.empty()) throw BagRecorderError("cannot record to " + path_ + ": it is " + kind + ", not a bag file");
  const std::string kept = kept_path_for(path_);
  if (std::rename(path_.c_str(), kept.c_str()) != 0) {
    throw BagRecorderError("cannot record to " + path_ + ": a file is there and cannot be moved to " + kept + ": " +
                           std::strerror(errno));
  }
  earlier_bag_kept_as_ = kept;
}

std::string BagRecorder::free_space_note() const {
  const std::string directory = bag_directory(path_);
  try {
    return " (" + std::to_string(free_disk_space(directory)) + " bytes free in " + directory + ")";
  } catch (const BagRecorderError&) {
    return "";
  }
}

BagRecorder::Compression BagRecorder::parse_compression(const std::string& name) {
  if (name == "lz4") return Compression::kLz4;
  if (name == "bz2") return Compression::kBz2;
  if (name == "none") return Compression::kNone;
  throw std::invalid_argument("unknown bag compression '" + name + "' (expected lz4, bz2 or none)");
}

}  // namespace birkhoff_cart
