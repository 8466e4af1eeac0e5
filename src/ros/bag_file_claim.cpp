// BagFileClaim and the checks of a bag path (bag_file_claim.h).
#include "birkhoff_cart/ros/bag_file_claim.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <thread>
#include <utility>

namespace birkhoff_cart {
namespace {

// An unlocked ".active" modified this recently may be a claim being made (created, not yet
// locked: a matter of microseconds) or a file a program that takes no lock is writing; either way
// it is not yet taken for a killed run's. [s of wall time]
constexpr double kCreationGrace = 2.0;
constexpr auto kRetryPause = std::chrono::milliseconds(20);
// An unlocked ".active" still being modified after this long belongs to a writer that takes no
// lock: refused rather than moved from under it. [s of wall time]
constexpr auto kGiveUp = std::chrono::seconds(10);

std::string kind_of(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISLNK(mode)) return "a symbolic link";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISSOCK(mode)) return "a socket";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  return "not a regular file";
}

/// Closes the descriptor (and so releases a lock taken through it) when it goes out of scope.
class OpenFile {
 public:
  explicit OpenFile(int descriptor) : descriptor_(descriptor) {}
  ~OpenFile() {
    if (descriptor_ >= 0) ::close(descriptor_);
  }
  OpenFile(const OpenFile&) = delete;
  OpenFile& operator=(const OpenFile&) = delete;
  int get() const { return descriptor_; }
  int release() { return std::exchange(descriptor_, -1); }

 private:
  int descriptor_;
};

}  // namespace

std::string bag_stem(const std::string& bag_path) {
  const std::string suffix = ".bag";
  const bool has_suffix =
      bag_path.size() > suffix.size() && bag_path.compare(bag_path.size() - suffix.size(), suffix.size(), suffix) == 0;
  return has_suffix ? bag_path.substr(0, bag_path.size() - suffix.size()) : bag_path;
}

std::string non_regular_file_kind(const std::string& path) {
  struct stat info;
  if (::lstat(path.c_str(), &info) != 0) return "";  // absent (or unreadable: opening it says why)
  return S_ISREG(info.st_mode) ? "" : kind_of(info.st_mode);
}

std::string kept_path_for(const std::string& bag_path, const std::string& suffix) {
  const std::string earlier = bag_path + suffix;
  struct stat info;
  if (::stat(earlier.c_str(), &info) != 0) {
    throw BagRecorderError("cannot read " + earlier + ": " + std::strerror(errno));
  }
  std::tm utc{};
  const std::time_t modified = info.st_mtime;
  ::gmtime_r(&modified, &utc);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "%Y%m%d-%H%M%S", &utc);
  const std::string stem = bag_stem(bag_path) + "_" + stamp;
  std::string kept = stem + ".bag" + suffix;
  for (int k = 2; ::access(kept.c_str(), F_OK) == 0; ++k) kept = stem + "-" + std::to_string(k) + ".bag" + suffix;
  return kept;
}

std::unique_ptr<BagFileClaim> BagFileClaim::claim(const std::string& bag_path, std::string& kept_as) {
  const std::string active = bag_path + ".active";
  const auto give_up = std::chrono::steady_clock::now() + kGiveUp;
  kept_as.clear();
  while (true) {
    const std::string kind = non_regular_file_kind(active);
    if (!kind.empty()) {
      throw BagRecorderError("cannot record to " + bag_path + ": " + active + " is " + kind +
                             ", not a bag being written (it is left as it is)");
    }
    OpenFile created(::open(active.c_str(), O_RDWR | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644));
    if (created.get() >= 0) {
      // A prober that took the lock of this new, empty file first lets go of it at once (it is
      // too fresh to be a killed run's): wait for that, never longer.
      while (::flock(created.get(), LOCK_EX) != 0) {
        if (errno != EINTR) throw BagRecorderError("cannot lock " + active + ": " + std::strerror(errno));
      }
      return std::unique_ptr<BagFileClaim>(new BagFileClaim(created.release(), active));
    }
    if (errno != EEXIST) throw BagRecorderError("cannot create " + active + ": " + std::strerror(errno));

    // A file is there: a running recorder's (locked) or a killed run's (unlocked).
    OpenFile found(::open(active.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC));
    if (found.get() < 0) {
      if (errno == ENOENT || errno == ELOOP) continue;  // moved meanwhile, or now a link: look again
      throw BagRecorderError("cannot open " + active + ": " + std::strerror(errno));
    }
    if (::flock(found.get(), LOCK_EX | LOCK_NB) != 0) {
      if (errno == EWOULDBLOCK) return nullptr;
      throw BagRecorderError("cannot lock " + active + ": " + std::strerror(errno));
    }
    // Only a lock holder renames: if the path names another file now, the one locked was moved.
    struct stat opened;
    struct stat at_path;
    if (::fstat(found.get(), &opened) != 0 || ::lstat(active.c_str(), &at_path) != 0 ||
        opened.st_ino != at_path.st_ino || opened.st_dev != at_path.st_dev) {
      continue;
    }
    const double age = std::difftime(std::time(nullptr), opened.st_mtime);  // [s]
    if (age < kCreationGrace) {
      if (std::chrono::steady_clock::now() > give_up) {
        throw BagRecorderError("cannot record to " + bag_path + ": " + active +
                               " is being written by a program that holds no lock on it (modified in the last " +
                               std::to_string(static_cast<int>(kCreationGrace)) + " s for " +
                               std::to_string(kGiveUp.count()) + " s); choose another ~bag_path");
      }
      std::this_thread::sleep_for(kRetryPause);
      continue;
    }
    const std::string kept = kept_path_for(bag_path, ".active");
    if (std::rename(active.c_str(), kept.c_str()) != 0) {
      throw BagRecorderError("cannot record to " + bag_path + ": the unfinished bag of a killed run at " + active +
                             " cannot be moved to " + kept + ": " + std::strerror(errno));
    }
    kept_as = kept;
  }
}

BagFileClaim::~BagFileClaim() { ::close(descriptor_); }

}  // namespace birkhoff_cart
