// The node's compressed rosbag record (see bag_recorder.h).
#include "birkhoff_cart/ros/bag_recorder.h"

#include <sys/stat.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <stdexcept>


namespace birkhoff_cart {

std::string bag_directory(const std::string& bag_path) {
  const std::size_t slash = bag_path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  if (slash == 0) return "/";
  return bag_path.substr(0, slash);
}

std::string run_bag_path(const std::string& bag_path, std::uint64_t run) {
  if (run <= 1) return bag_path;
  const std::string suffix = ".bag";
  const bool has_suffix =
      bag_path.size() > suffix.size() && bag_path.compare(bag_path.size() - suffix.size(), suffix.size(), suffix) == 0;
  const std::string stem = has_suffix ? bag_path.substr(0, bag_path.size() - suffix.size()) : bag_path;
  return stem + "_run" + std::to_string(run) + (has_suffix ? suffix : "");
}

std::string kept_path_for(const std::string& bag_path) {
  struct stat info;
  if (::stat(bag_path.c_str(), &info) != 0) {
    throw BagRecorderError("cannot read " + bag_path + ": " + std::strerror(errno));
  }
  std::tm utc{};
  const std::time_t modified = info.st_mtime;
  ::gmtime_r(&modified, &utc);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "%Y%m%d-%H%M%S", &utc);
  const std::string suffix = ".bag";
  const bool has_suffix =
      bag_path.size() > suffix.size() && bag_path.compare(bag_path.size() - suffix.size(), suffix.size(), suffix) == 0;
  const std::string stem = (has_suffix ? bag_path.substr(0, bag_path.size() - suffix.size()) : bag_path) + "_" + stamp;
  std::string kept = stem + suffix;
  for (int k = 2; ::access(kept.c_str(), F_OK) == 0; ++k) kept = stem + "-" + std::to_string(k) + suffix;
  return kept;
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
  if (::access(path.c_str(), F_OK) == 0) {  // an earlier bag: kept under its time, never overwritten
    const std::string kept = kept_path_for(path);
    if (std::rename(path.c_str(), kept.c_str()) != 0) {
      throw BagRecorderError("cannot record to " + path + ": a file is there and cannot be moved to " + kept + ": " +
                             std::strerror(errno));
    }
    earlier_bag_kept_as_ = kept;
  }
  BagFileWriter::Compression file_compression = BagFileWriter::Compression::kLz4;
  switch (compression) {
    case Compression::kNone: file_compression = BagFileWriter::Compression::kNone; break;
    case Compression::kLz4: file_compression = BagFileWriter::Compression::kLz4; break;
    case Compression::kBz2: file_compression = BagFileWriter::Compression::kBz2; break;
  }
  try {
    bag_ = std::make_unique<BagFileWriter>(active_path(), file_compression);
  } catch (const BagFileError& error) {
    throw BagRecorderError("cannot open bag " + active_path() + " for writing: " + error.what());
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
  if (std::rename(active_path().c_str(), path_.c_str()) != 0) {
    throw BagRecorderError("cannot rename " + active_path() + " to " + path_);
  }
  finished_ = true;
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
