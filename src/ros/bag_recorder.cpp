// The node's compressed rosbag record (see bag_recorder.h).
#include "birkhoff_cart/ros/bag_recorder.h"

#include <sys/statvfs.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>

#include <rosbag/exceptions.h>

namespace birkhoff_cart {

std::string bag_directory(const std::string& bag_path) {
  const std::size_t slash = bag_path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  if (slash == 0) return "/";
  return bag_path.substr(0, slash);
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
    : path_(path) {
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
  bag_ = std::make_unique<rosbag::Bag>();
  try {
    bag_->open(active_path(), rosbag::bagmode::Write);
  } catch (const rosbag::BagException& error) {
    throw BagRecorderError("cannot open bag " + active_path() + " for writing: " + error.what());
  }
  switch (compression) {
    case Compression::kNone: bag_->setCompression(rosbag::compression::Uncompressed); break;
    case Compression::kLz4: bag_->setCompression(rosbag::compression::LZ4); break;
    case Compression::kBz2: bag_->setCompression(rosbag::compression::BZ2); break;
  }
  open_ = true;
}

BagRecorder::~BagRecorder() {
  try {
    close();
  } catch (...) {
    // A destructor must not throw; close() already reported what it could.
  }
}

void BagRecorder::close() {
  if (!open_) return;
  open_ = false;
  try {
    bag_->close();
  } catch (const std::exception& error) {
    // rosbag::Bag's destructor would retry the same close and throw out of a destructor
    // (std::terminate). Let the half-closed Bag go instead; process exit closes its file, and the
    // chunks already written stay in "<path>.active" for `rosbag reindex`.
    static_cast<void>(bag_.release());
    throw BagRecorderError("cannot close bag " + active_path() + " (left as it is): " + error.what());
  }
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
