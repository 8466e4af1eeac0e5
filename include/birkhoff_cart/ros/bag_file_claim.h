// Which file a recorder may write, and keeping it its own while it writes (docs/ros_interface.md,
// "The bag"). A recorder writes "<path>.active" and renames it to <path> once the bag is complete.
// Several cart_sim nodes may be given one path (two launches on one master, a respawn, nodelets
// in one manager), so the ".active" file is claimed: created with O_EXCL and held under an
// exclusive flock(2) for as long as its recorder writes it. Then
//  - a second recorder finds the file locked and records elsewhere (BagRecorder): never into,
//    over or under another recorder's live file;
//  - an unlocked ".active" is what a killed run left (SIGKILL, a second signal, a power cut): a
//    crash record `rosbag reindex` recovers, kept aside under its modification time like an
//    earlier bag, never truncated;
//  - only the holder of a file's lock renames it (a prober that takes the lock of a file someone
//    renamed meanwhile sees another inode at the path and starts again).
// A path that exists and is not a regular file (a directory, a FIFO, a device, a symbolic link)
// is refused by name: never moved aside, never written.
#pragma once

#include <memory>
#include <stdexcept>
#include <string>

namespace birkhoff_cart {

/// The bag cannot be opened or written (the message names the path and the reason).
class BagRecorderError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// `bag_path` without its ".bag" suffix ("run.bag" → "run"; a path without the suffix unchanged).
std::string bag_stem(const std::string& bag_path);

/// What is at `path` when it is neither absent nor a regular file ("a directory", "a symbolic
/// link", "a FIFO", ...); "" when nothing is there or a regular file is (lstat: a link is not followed).
std::string non_regular_file_kind(const std::string& path);

/// The name an earlier bag at `bag_path` + `suffix` is kept under: "<stem>_<its modification time,
/// UTC, YYYYMMDD-HHMMSS>.bag" + `suffix`, with "-2", "-3", ... after the time when that name is
/// taken too (<stem> is `bag_path` without ".bag"). Throws BagRecorderError when the file cannot
/// be read (stat).
std::string kept_path_for(const std::string& bag_path, const std::string& suffix = "");

/// One recorder's claim on "<bag_path>.active": the open, locked file. Destroying it releases the
/// lock (the recorder first renames the file to its final name).
class BagFileClaim {
 public:
  /// Claims "<bag_path>.active": creates it (empty) and locks it. An unlocked file already there
  /// (a killed run's) is first renamed to kept_path_for(bag_path, ".active"), which `kept_as`
  /// receives ("" when there was none). Returns nullptr when another running recorder holds the
  /// file. Throws BagRecorderError naming the path and the reason when it cannot (missing or
  /// unwritable directory, "<bag_path>.active" not a regular file).
  static std::unique_ptr<BagFileClaim> claim(const std::string& bag_path, std::string& kept_as);
  ~BagFileClaim();
  BagFileClaim(const BagFileClaim&) = delete;
  BagFileClaim& operator=(const BagFileClaim&) = delete;

  /// The open file (read-write, empty when claimed); the lock lives as long as this object.
  int descriptor() const { return descriptor_; }
  /// "<bag_path>.active".
  const std::string& path() const { return path_; }

 private:
  BagFileClaim(int descriptor, std::string path) : descriptor_(descriptor), path_(std::move(path)) {}

  int descriptor_;
  std::string path_;
};

}  // namespace birkhoff_cart
