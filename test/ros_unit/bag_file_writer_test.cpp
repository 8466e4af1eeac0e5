// BagFileWriter (the node's sequential rosbag 2.0 writer): uncompressed it writes the very bytes
// rosbag::Bag writes for the same messages (several chunks, several types, a topic whose times go
// back); with every compression rosbag's C++ reader (rosbag::View) and its Python reader
// (rosbag.Bag) read back each message, in order, without reindexing; every finished chunk is in
// the file with its index records before the next one begins (`rosbag reindex` recovers all of
// them from a killed writer's file); a file left without close() is unindexed; misuse and
// unwritable paths throw naming the problem. No master needed; every file lives in a scratch directory removed at the end.
#include <gtest/gtest.h>

#include <stdlib.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <nav_msgs/Odometry.h>
#include <rosbag/bag.h>
#include <rosbag/exceptions.h>
#include <rosbag/view.h>
#include <sensor_msgs/JointState.h>
#include <std_msgs/Float64.h>
#include <tf2_msgs/TFMessage.h>

#include "birkhoff_cart/IntegrationError.h"
#include "birkhoff_cart/ros/bag_file_writer.h"

namespace birkhoff_cart {
namespace {

constexpr std::uint32_t kSmallChunk = 4096;  // [bytes]: several chunks from a few hundred messages
constexpr int kInstants = 300;                // publish instants written per bag

class ScratchDirectory {
 public:
  ScratchDirectory() {
    char pattern[] = "/tmp/bag_file_writer_test.XXXXXX";
    const char* made = ::mkdtemp(pattern);
    if (made != nullptr) path_ = made;
  }
  ~ScratchDirectory() {
    for (const std::string& file : files_) std::remove(file.c_str());
    if (!path_.empty()) ::rmdir(path_.c_str());
  }
  std::string file(const std::string& name) {
    files_.push_back(path_ + "/" + name);
    return files_.back();
  }
  bool ok() const { return !path_.empty(); }

 private:
  std::string path_;
  std::vector<std::string> files_;
};

std::vector<char> bytes_of(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<char>(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

/// One instant as the node records it: integration_error, odom, joint_states, tf, and a command
/// stamped a little earlier than the instant (times on /steering_torque go back within a chunk
/// relative to other topics; on its own topic every 7th goes back too).
template <class Writer>
void write_instant(Writer& writer, int k) {
  const ros::Time time(0.01 * k);
  IntegrationError error;
  error.header.stamp = time;
  error.integrator = "birkhoff2";
  error.step_size = 1e-3;
  error.steps_taken = 10u * static_cast<unsigned>(k);
  error.energy = 1.0 + 1e-3 * k;
  nav_msgs::Odometry odometry;
  odometry.header.stamp = time;
  odometry.header.frame_id = "odom";
  odometry.child_frame_id = "base_link";
  odometry.pose.pose.position.x = 0.01 * k;
  odometry.pose.pose.orientation.w = 1.0;
  sensor_msgs::JointState joints;
  joints.header.stamp = time;
  joints.name = {"steering_joint", "rear_left_wheel_joint"};
  joints.position = {0.1 * k, 0.2 * k};
  tf2_msgs::TFMessage transforms;
  transforms.transforms.resize(1);
  transforms.transforms[0].header.stamp = time;
  transforms.transforms[0].transform.rotation.w = 1.0;
  std_msgs::Float64 command;
  command.data = 0.5 * k;
  writer.write("/cart_sim/integration_error", time, error);
  writer.write("/odom", time, odometry);
  writer.write("/joint_states", time, joints);
  writer.write("/tf", time, transforms);
  const double back = k % 7 == 0 ? 0.015 : 0.005;  // [s]
  writer.write("/steering_torque", ros::Time(std::max(1e-9, 0.01 * k - back)), command);
}

TEST(BagFileWriter, UncompressedBagIsByteForByteRosbags) {
  ScratchDirectory scratch;
  ASSERT_TRUE(scratch.ok());
  const std::string ours = scratch.file("ours.bag");
  const std::string theirs = scratch.file("rosbag.bag");
  {
    BagFileWriter writer(ours, BagFileWriter::Compression::kNone, kSmallChunk);
    for (int k = 1; k <= kInstants; ++k) write_instant(writer, k);
    writer.close();
  }
  {
    rosbag::Bag bag(theirs, rosbag::bagmode::Write);
    bag.setCompression(rosbag::compression::Uncompressed);
    bag.setChunkThreshold(kSmallChunk);
    for (int k = 1; k <= kInstants; ++k) write_instant(bag, k);
    bag.close();
  }
  const std::vector<char> our_bytes = bytes_of(ours);
  const std::vector<char> their_bytes = bytes_of(theirs);
  ASSERT_GT(their_bytes.size(), 20u * kSmallChunk) << "expected several chunks";
  ASSERT_EQ(our_bytes.size(), their_bytes.size());
  std::size_t first_difference = 0;
  while (first_difference < our_bytes.size() && our_bytes[first_difference] == their_bytes[first_difference]) {
    ++first_difference;
  }
  EXPECT_EQ(first_difference, our_bytes.size()) << "the files differ first at byte " << first_difference;
}

class BagFileWriterCompression : public ::testing::TestWithParam<BagFileWriter::Compression> {};

/// kInstants publish instants in small chunks, closed (indexed).
void write_closed_bag(const std::string& path, BagFileWriter::Compression compression) {
  BagFileWriter writer(path, compression, kSmallChunk);
  for (int k = 1; k <= kInstants; ++k) write_instant(writer, k);
  writer.close();
}

TEST_P(BagFileWriterCompression, RosbagReadsEveryMessageBackWithoutReindexing) {
  ScratchDirectory scratch;
  ASSERT_TRUE(scratch.ok());
  const std::string path = scratch.file("compressed.bag");
  write_closed_bag(path, GetParam());
  rosbag::Bag bag(path, rosbag::bagmode::Read);  // throws BagUnindexedException for an unindexed bag
  rosbag::View odometry_view(bag, rosbag::TopicQuery(std::vector<std::string>{"/odom"}));
  ASSERT_EQ(odometry_view.size(), static_cast<unsigned>(kInstants));
  int k = 0;
  for (const rosbag::MessageInstance& instance : odometry_view) {
    ++k;
    const nav_msgs::Odometry::ConstPtr odometry = instance.instantiate<nav_msgs::Odometry>();
    ASSERT_TRUE(odometry != nullptr);
    EXPECT_EQ(instance.getTime(), ros::Time(0.01 * k));
    EXPECT_EQ(odometry->pose.pose.position.x, 0.01 * k);
    EXPECT_EQ(odometry->child_frame_id, "base_link");
  }
  rosbag::View command_view(bag, rosbag::TopicQuery(std::vector<std::string>{"/steering_torque"}));
  EXPECT_EQ(command_view.size(), static_cast<unsigned>(kInstants));
  ros::Time previous;
  for (const rosbag::MessageInstance& instance : command_view) {
    EXPECT_GE(instance.getTime(), previous) << "the index is not in time order";
    previous = instance.getTime();
  }
  rosbag::View everything(bag);
  EXPECT_EQ(everything.size(), 5u * kInstants);
}

// rosbag's Python reader (rosbag.Bag, message classes generated from the definitions the bag
// carries): every topic's count, the odometry values and times, each topic in time order. It
// raises ROSBagUnindexedException for an unindexed bag and ROSBagException for a bad record.
constexpr char kPythonReader[] = R"(import sys, rosbag
with rosbag.Bag(sys.argv[1]) as bag:
    counts, previous, odometry_ok, in_order = {}, {}, True, True
    for topic, message, time in bag.read_messages():
        counts[topic] = counts.get(topic, 0) + 1
        in_order = in_order and previous.get(topic, time) <= time
        previous[topic] = time
        if topic == "/odom":
            k = counts[topic]
            odometry_ok = (odometry_ok and message.pose.pose.position.x == 0.01 * k
                           and time == message.header.stamp and abs(time.to_sec() - 0.01 * k) < 1e-9
                           and message.child_frame_id == "base_link")
    for topic in sorted(counts):
        print("count", topic, counts[topic])
    print("odometry_ok", int(odometry_ok))
    print("in_order", int(in_order))
)";

TEST_P(BagFileWriterCompression, RosbagsPythonReaderReadsEveryMessage) {
  ScratchDirectory scratch;
  ASSERT_TRUE(scratch.ok());
  const std::string path = scratch.file("compressed.bag");
  write_closed_bag(path, GetParam());
  const std::string script = scratch.file("read_bag.py");
  std::ofstream(script) << kPythonReader;
  const std::string output_path = scratch.file("read_bag.out");
  const std::string command = "/usr/bin/python3 " + script + " " + path + " > " + output_path + " 2>&1";
  const int status = std::system(command.c_str());
  const std::vector<char> raw = bytes_of(output_path);
  const std::string output(raw.begin(), raw.end());
  ASSERT_EQ(status, 0) << command << "\n" << output;
  const std::string n = std::to_string(kInstants);
  EXPECT_EQ(output, "count /cart_sim/integration_error " + n + "\ncount /joint_states " + n + "\ncount /odom " + n +
                        "\ncount /steering_torque " + n + "\ncount /tf " + n + "\nodometry_ok 1\nin_order 1\n");
}

INSTANTIATE_TEST_SUITE_P(EveryCompression, BagFileWriterCompression,
                         ::testing::Values(BagFileWriter::Compression::kNone, BagFileWriter::Compression::kLz4,
                                           BagFileWriter::Compression::kBz2),
                         [](const ::testing::TestParamInfo<BagFileWriter::Compression>& info) {
                           return std::string(BagFileWriter::compression_name(info.param));
                         });

// rosbag's own recovery of a killed recorder's file (`rosbag reindex`, rosbag.Bag.reindex): it
// keeps every chunk that is followed by its whole index records. Prints the /odom messages recovered.
constexpr char kPythonReindex[] = R"(import sys, rosbag
with rosbag.Bag(sys.argv[1], "a", allow_unindexed=True) as bag:
    for _ in bag.reindex():
        pass
with rosbag.Bag(sys.argv[1]) as bag:
    print(bag.get_message_count("/odom"))
)";

// A writer killed at any moment (SIGKILL: the stdio buffer is lost, what write(2) handed to the
// kernel stays) leaves every chunk it finished with the chunk's index records in the file: copied
// right after a chunk went out (the file grew), the file reindexes to every message written so far.
TEST_P(BagFileWriterCompression, EveryFinishedChunkIsInTheFileWithItsIndexRecords) {
  ScratchDirectory scratch;
  ASSERT_TRUE(scratch.ok());
  const std::string path = scratch.file("killed.bag.active");
  const std::string copy = scratch.file("copy.bag.active");
  const std::string script = scratch.file("reindex.py");
  const std::string output_path = scratch.file("reindex.out");
  std::ofstream(script) << kPythonReindex;
  BagFileWriter writer(path, GetParam(), kSmallChunk);
  nav_msgs::Odometry odometry;
  odometry.header.frame_id = "odom";
  std::size_t size = bytes_of(path).size();
  int chunks_seen = 0;
  for (int k = 1; chunks_seen < 3 && k < 10000; ++k) {
    odometry.header.stamp = ros::Time(0.01 * k);
    odometry.pose.pose.position.x = 0.01 * k;
    writer.write("/odom", odometry.header.stamp, odometry);
    const std::vector<char> on_disk = bytes_of(path);  // what a SIGKILL now would leave
    if (on_disk.size() == size) continue;
    size = on_disk.size();
    ++chunks_seen;
    // A chunk went out with message k: every message so far is in finished chunks.
    std::ofstream(copy, std::ios::binary).write(on_disk.data(), static_cast<std::streamsize>(on_disk.size()));
    const std::string command = "/usr/bin/python3 " + script + " " + copy + " > " + output_path + " 2>&1";
    const int status = std::system(command.c_str());
    const std::vector<char> raw = bytes_of(output_path);
    const std::string output(raw.begin(), raw.end());
    ASSERT_EQ(status, 0) << command << "\n" << output;
    EXPECT_EQ(output, std::to_string(k) + "\n") << "after chunk " << chunks_seen << " (message " << k << ")";
  }
  EXPECT_EQ(chunks_seen, 3);
}

TEST(BagFileWriter, AFileNeverClosedIsUnindexed) {
  ScratchDirectory scratch;
  ASSERT_TRUE(scratch.ok());
  const std::string path = scratch.file("unclosed.bag");
  {
    BagFileWriter writer(path, BagFileWriter::Compression::kLz4, kSmallChunk);
    for (int k = 1; k <= kInstants; ++k) write_instant(writer, k);
  }  // destroyed without close(): like a process killed mid-run
  EXPECT_THROW(rosbag::Bag(path, rosbag::bagmode::Read), rosbag::BagUnindexedException);
}

TEST(BagFileWriter, MisuseAndUnwritablePathsThrowNamingTheProblem) {
  ScratchDirectory scratch;
  ASSERT_TRUE(scratch.ok());
  try {
    BagFileWriter writer("/nonexistent_directory_for_bag_file_writer_test/x.bag", BagFileWriter::Compression::kNone);
    FAIL() << "opening in a missing directory should throw";
  } catch (const BagFileError& error) {
    EXPECT_NE(std::string(error.what()).find("/nonexistent_directory_for_bag_file_writer_test/x.bag"),
              std::string::npos)
        << error.what();
  }
  const std::string path = scratch.file("misuse.bag");
  BagFileWriter writer(path, BagFileWriter::Compression::kNone);
  std_msgs::Float64 command;
  writer.write("/steering_torque", ros::Time(1.0), command);
  nav_msgs::Odometry odometry;
  try {
    writer.write("/steering_torque", ros::Time(2.0), odometry);
    FAIL() << "a second type on one topic should throw";
  } catch (const BagFileError& error) {
    EXPECT_NE(std::string(error.what()).find("std_msgs/Float64"), std::string::npos) << error.what();
  }
  writer.close();
  EXPECT_THROW(writer.write("/steering_torque", ros::Time(3.0), command), BagFileError);
  rosbag::Bag bag(path, rosbag::bagmode::Read);
  EXPECT_EQ(rosbag::View(bag).size(), 1u);
}

}  // namespace
}  // namespace birkhoff_cart
