// One bag file per recorder (BagFileClaim, BagRecorder): a second recorder on a path another
// running recorder holds (in this process, as nodelets in one manager, or in another process, as
// two launches on one master) records to its own "<stem>_pid<pid>.bag" and each bag is complete;
// a killed run's "<path>.active" is kept aside byte for byte under its time, never truncated; a
// path that is a directory, a FIFO or a symbolic link (or a directory at "<path>.active") is
// refused by name and left as it is; a file put at the path while recording is kept aside at
// close, never written over. No master needed; files in a scratch directory removed at the end.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <sys/time.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <std_msgs/Float64.h>

#include "birkhoff_cart/ros/bag_file_writer.h"
#include "birkhoff_cart/ros/bag_recorder.h"

namespace birkhoff_cart {
namespace {

constexpr double kAnHourAgo = 3600.0;  // [s]: a killed run's file, well past the creation grace

class ScratchDirectory {
 public:
  ScratchDirectory() {
    char pattern[] = "/tmp/bag_file_claim_test.XXXXXX";
    const char* made = ::mkdtemp(pattern);
    if (made != nullptr) path_ = made;
  }
  ~ScratchDirectory() {
    if (!path_.empty()) std::system(("rm -rf " + path_).c_str());
  }
  std::string file(const std::string& name) const { return path_ + "/" + name; }
  bool ok() const { return !path_.empty(); }
  /// The names in the directory, sorted.
  std::vector<std::string> names() const {
    std::vector<std::string> found;
    FILE* listing = ::popen(("ls -A " + path_).c_str(), "r");
    char line[4096];
    while (listing != nullptr && std::fgets(line, sizeof line, listing) != nullptr) {
      std::string name(line);
      if (!name.empty() && name.back() == '\n') name.pop_back();
      found.push_back(name);
    }
    if (listing != nullptr) ::pclose(listing);
    return found;
  }

 private:
  std::string path_;
};

std::vector<char> bytes_of(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<char>(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void write_command(BagRecorder& recorder, double value) {
  std_msgs::Float64 command;
  command.data = value;
  recorder.write("/steering_torque", ros::Time(value), command);
}

/// The values of the commands in the complete bag at `path`, in order.
std::vector<double> commands_in(const std::string& path) {
  rosbag::Bag bag(path, rosbag::bagmode::Read);
  std::vector<double> values;
  for (const rosbag::MessageInstance& instance : rosbag::View(bag)) {
    values.push_back(instance.instantiate<std_msgs::Float64>()->data);
  }
  return values;
}

TEST(BagFileClaim, ASecondRecorderOnATakenPathRecordsToItsOwnFile) {
  ScratchDirectory scratch;
  ASSERT_TRUE(scratch.ok());
  const std::string path = scratch.file("run.bag");
  BagRecorder first(path, BagRecorder::Compression::kLz4);
  BagRecorder second(path, BagRecorder::Compression::kLz4);
  BagRecorder third(path, BagRecorder::Compression::kLz4);
  EXPECT_EQ(first.path(), path);
  EXPECT_EQ(first.taken_path(), "");
  const std::string own = scratch.file("run_pid" + std::to_string(::getpid()) + ".bag");
  EXPECT_EQ(second.path(), own);
  EXPECT_EQ(second.taken_path(), path);
  EXPECT_EQ(third.path(), scratch.file("run_pid" + std::to_string(::getpid()) + "-2.bag"));
  write_command(first, 1.0);
  write_command(second, 2.0);
  write_command(third, 3.0);
  write_command(first, 1.5);
  second.close();  // the later recorder finishes first: nothing of the first one's moves
  EXPECT_EQ(second.current_path(), own);
  EXPECT_TRUE(first.is_open());
  first.close();
  third.close();
  EXPECT_EQ(first.current_path(), path);
  EXPECT_EQ(commands_in(path), (std::vector<double>{1.0, 1.5}));
  EXPECT_EQ(commands_in(own), (std::vector<double>{2.0}));
  EXPECT_EQ(commands_in(third.path()), (std::vector<double>{3.0}));
  EXPECT_EQ(first.earlier_bag_kept_as(), "");
  EXPECT_EQ(second.earlier_bag_kept_as(), "");
  EXPECT_EQ(scratch.names().size(), 3u) << "no .active file or kept copy is left";
}

TEST(BagFileClaim, ARecorderOfAnotherProcessHoldsItsPath) {
  ScratchDirectory scratch;
  ASSERT_TRUE(scratch.ok());
  const std::string path = scratch.file("run.bag");
  int ready[2];
  int go[2];
  ASSERT_EQ(::pipe(ready), 0);
  ASSERT_EQ(::pipe(go), 0);
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {  // another process recording to the same path (as a second launch would)
    int status = 1;
    {
      BagRecorder recorder(path, BagRecorder::Compression::kNone);
      write_command(recorder, 7.0);
      char byte = 1;
      if (::write(ready[1], &byte, 1) == 1 && ::read(go[0], &byte, 1) == 1) {
        recorder.close();
        status = recorder.path() == path ? 0 : 1;
      }
    }
    ::_exit(status);
  }
  char byte = 0;
  ASSERT_EQ(::read(ready[0], &byte, 1), 1);
  std::string mine;
  {
    BagRecorder recorder(path, BagRecorder::Compression::kNone);
    mine = recorder.path();
    EXPECT_EQ(recorder.taken_path(), path);
    write_command(recorder, 8.0);
    EXPECT_EQ(::write(go[1], &byte, 1), 1);  // the other one closes and renames its own file
    int status = -1;
    ASSERT_EQ(::waitpid(child, &status, 0), child);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "the other process's bag was not finished at " << path;
    recorder.close();
  }
  EXPECT_EQ(mine, scratch.file("run_pid" + std::to_string(::getpid()) + ".bag"));
  EXPECT_EQ(commands_in(path), (std::vector<double>{7.0}));
  EXPECT_EQ(commands_in(mine), (std::vector<double>{8.0}));
  for (int descriptor : {ready[0], ready[1], go[0], go[1]}) ::close(descriptor);
}

TEST(BagFileClaim, AKilledRunsActiveFileIsKeptAsideByteForByte) {
  ScratchDirectory scratch;
  ASSERT_TRUE(scratch.ok());
  const std::string path = scratch.file("run.bag");
  const std::string active = path + ".active";
  {
    // What a killed run leaves: chunks on disk, never closed (a destroyed writer closes its file
    // handle but writes no index), last written an hour ago.
    BagFileWriter killed(active, BagFileWriter::Compression::kLz4, 4096);
    std_msgs::Float64 command;
    for (int k = 1; k <= 2000; ++k) {
      command.data = k;
      killed.write("/steering_torque", ros::Time(0.001 * k), command);
    }
  }
  struct timeval old_times[2];
  ::gettimeofday(&old_times[0], nullptr);
  old_times[0].tv_sec -= static_cast<time_t>(kAnHourAgo);
  old_times[1] = old_times[0];
  ASSERT_EQ(::utimes(active.c_str(), old_times), 0);
  const std::vector<char> crash_record = bytes_of(active);
  ASSERT_GT(crash_record.size(), 8192u);
  const std::string expected_kept = kept_path_for(path, ".active");
  EXPECT_EQ(expected_kept.substr(expected_kept.size() - 11), ".bag.active") << expected_kept;
  {
    BagRecorder recorder(path, BagRecorder::Compression::kLz4);  // what a respawn does
    EXPECT_EQ(recorder.crash_record_kept_as(), expected_kept);
    EXPECT_EQ(recorder.path(), path);
    write_command(recorder, 1.0);
    recorder.close();
  }
  EXPECT_EQ(bytes_of(expected_kept), crash_record) << "the crash record was changed";
  EXPECT_EQ(commands_in(path), (std::vector<double>{1.0}));
}

TEST(BagFileClaim, PathsThatAreNotRegularFilesAreRefusedByNameAndLeftAsTheyAre) {
  ScratchDirectory scratch;
  ASSERT_TRUE(scratch.ok());
  const std::string directory = scratch.file("directory.bag");
  ASSERT_EQ(::mkdir(directory.c_str(), 0755), 0);
  std::ofstream(directory + "/inside") << "kept";
  const std::string fifo = scratch.file("fifo.bag");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0644), 0);
  const std::string target = scratch.file("target");
  std::ofstream(target) << "a file a link points to";
  const std::string link = scratch.file("link.bag");
  ASSERT_EQ(::symlink(target.c_str(), link.c_str()), 0);
  const std::string blocked = scratch.file("blocked.bag");
  ASSERT_EQ(::mkdir((blocked + ".active").c_str(), 0755), 0);
  const std::vector<std::string> before = scratch.names();
  const std::vector<std::pair<std::string, std::string>> cases = {
      {directory, directory + ": it is a directory"},
      {directory + "/", directory + "/: it is a directory"},
      {fifo, fifo + ": it is a FIFO"},
      {link, link + ": it is a symbolic link"},
      {blocked, blocked + ".active is a directory"},
  };
  for (const auto& [path, named] : cases) {
    try {
      BagRecorder recorder(path, BagRecorder::Compression::kLz4);
      ADD_FAILURE() << "recording to " << path << " should be refused";
    } catch (const BagRecorderError& error) {
      EXPECT_NE(std::string(error.what()).find(named), std::string::npos) << error.what();
    }
  }
  EXPECT_EQ(scratch.names(), before) << "something was created, moved or removed";
  EXPECT_EQ(bytes_of(directory + "/inside").size(), 4u);
  struct stat info;
  ASSERT_EQ(::lstat(link.c_str(), &info), 0);
  EXPECT_TRUE(S_ISLNK(info.st_mode));
}

TEST(BagFileClaim, AFilePutAtThePathWhileRecordingIsKeptAsideAtClose) {
  ScratchDirectory scratch;
  ASSERT_TRUE(scratch.ok());
  const std::string path = scratch.file("run.bag");
  BagRecorder recorder(path, BagRecorder::Compression::kNone);
  write_command(recorder, 1.0);
  std::ofstream(path) << "written by another program meanwhile";
  recorder.close();
  ASSERT_FALSE(recorder.earlier_bag_kept_as().empty());
  const std::vector<char> kept = bytes_of(recorder.earlier_bag_kept_as());
  EXPECT_EQ(std::string(kept.begin(), kept.end()), "written by another program meanwhile");
  EXPECT_EQ(commands_in(path), (std::vector<double>{1.0}));
}

TEST(OwnBagPath, NamesTheProcessAndCountsRecordersOfOneProcess) {
  EXPECT_EQ(own_bag_path("/tmp/run.bag", 42, 1), "/tmp/run_pid42.bag");
  EXPECT_EQ(own_bag_path("/tmp/run.bag", 42, 3), "/tmp/run_pid42-3.bag");
  EXPECT_EQ(own_bag_path("/tmp/record", 42, 1), "/tmp/record_pid42");
}

}  // namespace
}  // namespace birkhoff_cart
