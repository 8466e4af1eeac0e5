// The node's compressed rosbag record (see bag_recorder.h).
#include "birkhoff_cart/ros/bag_recorder.h"

#include <cstdio>
#include <stdexcept>

#include <rosbag/exceptions.h>

namespace birkhoff_cart {

BagRecorder::BagRecorder(const std::string& path, Compression compression) : path_(path) {
  if (path.empty()) throw BagRecorderError("bag path is empty");
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
  bag_->close();
  if (std::rename(active_path().c_str(), path_.c_str()) != 0) {
    throw BagRecorderError("cannot rename " + active_path() + " to " + path_);
  }
}

BagRecorder::Compression BagRecorder::parse_compression(const std::string& name) {
  if (name == "lz4") return Compression::kLz4;
  if (name == "bz2") return Compression::kBz2;
  if (name == "none") return Compression::kNone;
  throw std::invalid_argument("unknown bag compression '" + name + "' (expected lz4, bz2 or none)");
}

}  // namespace birkhoff_cart
