// rostest fault_signals: cart_sim's record survives faults (docs/hard_cases.md §10).
//  - SIGTERM during a real-time recording: exit 0, the bag is closed under its final name, readable,
//    and holds every published instant up to shutdown (odom stamps k/rate for k = 1..N with no gap,
//    N = the node's own "Published instants" count, the same N for joint_states and integration_error).
//  - SIGKILL during a fast recording: "<path>.active" is left behind, `rosbag reindex` recovers it,
//    and the recovered messages are a gap-free prefix of the run (the last, unfinished chunk is lost).
//  - an unwritable ~bag_path: non-zero exit at once, stderr names the path.
//  - determinism: two runs of the same scene with the same commands record bit-identical odom and
//    joint_states messages and identical integration_error fields except wall_time_per_step; both
//    bags hold the commands sent (values and count), recorded before the first published instant.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/JointState.h>
#include <std_msgs/Float64.h>

#include "birkhoff_cart/IntegrationError.h"
#include "test_helpers.h"

namespace {

constexpr double kWaitTimeout = 60.0;     // [s of wall time], only against hangs
constexpr double kPublishRate = 100.0;    // cart_sim's default ~publish_rate [Hz of scene time]
constexpr double kStampTolerance = 1e-6;  // [s]; stamps are t0 + k/rate in ROS time (ns)

using birkhoff_cart_test::file_exists;
using birkhoff_cart_test::file_size;
using birkhoff_cart_test::read_file;
using birkhoff_cart_test::run_command;
using birkhoff_cart_test::start_cart_sim;
using birkhoff_cart_test::wait_exit;

std::string scene_parameter() {
  std::string scene;
  ros::NodeHandle("~").getParam("scene", scene);
  return scene;
}

std::string scratch(const std::string& name) { return "/tmp/fault_signals_" + std::to_string(::getpid()) + "_" + name; }

/// Scene-time stamps of `topic` in bag order.
std::vector<double> stamps(const std::string& path, const std::string& topic) {
  rosbag::Bag bag(path, rosbag::bagmode::Read);
  rosbag::View view(bag, rosbag::TopicQuery(std::vector<std::string>{topic}));
  std::vector<double> times;
  for (const rosbag::MessageInstance& instance : view) times.push_back(instance.getTime().toSec());
  return times;
}

/// True when `times` are k/rate for k = 1..N: every publish instant, none missing.
bool gap_free_from_start(const std::vector<double>& times, std::string* why) {
  for (std::size_t k = 0; k < times.size(); ++k) {
    const double expected = static_cast<double>(k + 1) / kPublishRate;
    if (std::abs(times[k] - expected) > kStampTolerance) {
      *why = "message " + std::to_string(k) + " at t = " + std::to_string(times[k]) + " s, expected " +
             std::to_string(expected);
      return false;
    }
  }
  return true;
}

/// The number after "Published instants: " in the node's summary (−1 when absent).
long published_instants(const std::string& summary) {
  const std::string key = "Published instants: ";
  const std::size_t at = summary.find(key);
  return at == std::string::npos ? -1 : std::stol(summary.substr(at + key.size()));
}

TEST(FaultSignals, SigtermClosesTheBagWithEveryMessageUpToShutdown) {
  const std::string bag_path = scratch("sigterm.bag");
  const std::string summary = scratch("sigterm_summary.txt");
  const pid_t pid = start_cart_sim({"__name:=sigterm_sim", "_scene:=" + scene_parameter(), "_bag_path:=" + bag_path,
                                    "_fast:=false", "_duration:=0.0", "_summary_path:=" + summary},
                                   scratch("sigterm.log"));
  ASSERT_GT(pid, 0);
  ASSERT_TRUE(birkhoff_cart_test::wait_for([&] { return file_exists(bag_path + ".active"); }, kWaitTimeout));
  // 1.5 s of scene time, read from the node's own /odom stamps (not from the wall clock).
  ros::NodeHandle node;
  double odom_time = 0.0;  // [s of scene time]
  ros::Subscriber odom_subscriber = node.subscribe<nav_msgs::Odometry>(
      "/odom", 10, [&odom_time](const nav_msgs::Odometry::ConstPtr& message) { odom_time = message->header.stamp.toSec(); });
  ASSERT_TRUE(birkhoff_cart_test::wait_for([&] { return odom_time >= 1.5; }, kWaitTimeout)) << "t = " << odom_time;
  ASSERT_EQ(::kill(pid, SIGTERM), 0);
  EXPECT_EQ(wait_exit(pid, 30.0), 0) << read_file(scratch("sigterm.log"));
  ASSERT_TRUE(file_exists(bag_path));
  EXPECT_FALSE(file_exists(bag_path + ".active"));
  std::vector<double> odom;
  ASSERT_NO_THROW(odom = stamps(bag_path, "/odom"));
  std::string why;
  EXPECT_TRUE(gap_free_from_start(odom, &why)) << why;
  EXPECT_GT(odom.size(), 50u);
  EXPECT_EQ(stamps(bag_path, "/joint_states").size(), odom.size());
  EXPECT_EQ(stamps(bag_path, "/sigterm_sim/integration_error").size(), odom.size());
  // Every instant the node says it published is in the bag.
  EXPECT_EQ(published_instants(read_file(summary)), static_cast<long>(odom.size())) << read_file(summary);
  std::string info;
  EXPECT_EQ(run_command("rosbag info " + bag_path, &info), 0) << info;
  std::printf("[ measured ] SIGTERM after 1.5 s: %zu instants recorded, bag %ld bytes\n", odom.size(),
              file_size(bag_path));
  std::remove(bag_path.c_str());
  std::remove(summary.c_str());
}

TEST(FaultSignals, SigkillLeavesAnActiveBagThatRosbagReindexRecovers) {
  const std::string bag_path = scratch("sigkill.bag");
  const std::string active = bag_path + ".active";
  const pid_t pid = start_cart_sim({"__name:=sigkill_sim", "_scene:=" + scene_parameter(), "_bag_path:=" + bag_path,
                                    "_fast:=true", "_duration:=0.0", "_bag_compression:=none"},
                                   scratch("sigkill.log"));
  ASSERT_GT(pid, 0);
  // Wait until several chunks (rosbag's default chunk threshold is 768 KiB) are on disk.
  ASSERT_TRUE(birkhoff_cart_test::wait_for([&] { return file_size(active) > 4L * 1024 * 1024; }, kWaitTimeout))
      << "size " << file_size(active);
  ASSERT_EQ(::kill(pid, SIGKILL), 0);
  EXPECT_EQ(wait_exit(pid, 30.0), -1);
  ASSERT_TRUE(file_exists(active));
  EXPECT_FALSE(file_exists(bag_path));
  std::string output;
  EXPECT_NE(run_command("rosbag info " + active, &output), 0) << "an unindexed bag should need reindexing";
  output.clear();
  ASSERT_EQ(run_command("rosbag reindex " + active, &output), 0) << output;
  std::vector<double> odom;
  ASSERT_NO_THROW(odom = stamps(active, "/odom"));
  std::string why;
  EXPECT_TRUE(gap_free_from_start(odom, &why)) << why;
  EXPECT_GT(odom.size(), 100u);
  std::printf("[ measured ] SIGKILL at %ld bytes: rosbag reindex recovered %zu odom instants (t = %.2f s)\n",
              file_size(active), odom.size(), odom.empty() ? 0.0 : odom.back());
  std::remove(active.c_str());
  std::remove((bag_path + ".orig.active").c_str());
  std::remove(scratch("sigkill.orig.bag").c_str());
}

TEST(FaultSignals, UnwritableBagPathStopsTheNodeWithAMessageNamingIt) {
  const std::string log = scratch("unwritable.log");
  const pid_t pid = start_cart_sim({"__name:=unwritable_sim", "_scene:=" + scene_parameter(),
                                    "_bag_path:=/nonexistent_directory/cart.bag"},
                                   log);
  ASSERT_GT(pid, 0);
  const int status = wait_exit(pid, 30.0);
  EXPECT_NE(status, 0);
  EXPECT_NE(status, -1) << "cart_sim kept running without its record";
  EXPECT_NE(status, 127);
  EXPECT_NE(read_file(log).find("/nonexistent_directory/cart.bag"), std::string::npos) << read_file(log);
  std::remove(log.c_str());
}

TEST(FaultSignals, SceneStartingAtNegativeTimeStopsTheNodeAtStartWithExit2) {
  // Scene time is published as ROS time, which cannot be negative: the node must refuse at start
  // (exit 2, docs/ros_interface.md, "Node cart_sim"), not abort at its first /clock with the bag left unfinished.
  std::string scene = read_file(scene_parameter());
  const std::string start_line = "\n  time: 0.0";  // initial_state.time of driven.yaml
  const std::size_t at = scene.find(start_line);
  ASSERT_NE(at, std::string::npos) << "no initial_state time line in " << scene_parameter();
  scene.replace(at, start_line.size(), "\n  time: -0.5");
  const std::string scene_path = scratch("negative_start.yaml");
  std::ofstream(scene_path) << scene;
  const std::string bag_path = scratch("negative_start.bag");
  const std::string log = scratch("negative_start.log");
  const pid_t pid = start_cart_sim(
      {"__name:=negative_start_sim", "_scene:=" + scene_path, "_bag_path:=" + bag_path, "_fast:=true"}, log);
  ASSERT_GT(pid, 0);
  EXPECT_EQ(wait_exit(pid, 30.0), 2) << read_file(log);
  EXPECT_NE(read_file(log).find("starts at t = -0.5 s"), std::string::npos) << read_file(log);
  EXPECT_FALSE(file_exists(bag_path + ".active")) << "a bag was opened for a run that cannot start";
  EXPECT_FALSE(file_exists(bag_path));
  std::remove((bag_path + ".active").c_str());
  std::remove(log.c_str());
  std::remove(scene_path.c_str());
}

/// Runs the driven scene for 2 s of scene time, the same commands sent while it is paused.
std::string recorded_run(const std::string& name) {
  const std::string bag_path = scratch(name + ".bag");
  const pid_t pid = start_cart_sim({"__name:=" + name, "_scene:=" + scene_parameter(), "_bag_path:=" + bag_path,
                                    "_fast:=true", "_duration:=2.0", "_start_paused:=true",
                                    "steering_torque:=" + name + "/steering_torque",
                                    "drive_torque:=" + name + "/drive_torque"},
                                   scratch(name + ".log"));
  EXPECT_GT(pid, 0);
  ros::NodeHandle node;
  ros::Publisher steering = node.advertise<std_msgs::Float64>(name + "/steering_torque", 10);
  ros::Publisher drive = node.advertise<std_msgs::Float64>(name + "/drive_torque", 10);
  EXPECT_TRUE(birkhoff_cart_test::wait_for(
      [&] { return steering.getNumSubscribers() > 0 && drive.getNumSubscribers() > 0; }, kWaitTimeout));
  for (double torque : {0.4, 1.2, 0.8}) {
    std_msgs::Float64 message;
    message.data = torque;
    steering.publish(message);
  }
  std_msgs::Float64 message;
  message.data = 25.0;
  drive.publish(message);
  ros::WallDuration(0.5).sleep();  // delivery before the run starts
  EXPECT_TRUE(birkhoff_cart_test::set_paused("/" + name + "/pause", false));
  EXPECT_EQ(wait_exit(pid, kWaitTimeout), 0) << read_file(scratch(name + ".log"));
  return bag_path;
}

/// Serialized bytes of every message on `topic`, in order.
std::vector<std::vector<uint8_t>> raw_messages(const std::string& path, const std::string& topic) {
  rosbag::Bag bag(path, rosbag::bagmode::Read);
  rosbag::View view(bag, rosbag::TopicQuery(std::vector<std::string>{topic}));
  std::vector<std::vector<uint8_t>> messages;
  for (const rosbag::MessageInstance& instance : view) {
    std::vector<uint8_t> bytes(instance.size());
    ros::serialization::OStream stream(bytes.data(), static_cast<uint32_t>(bytes.size()));
    instance.write(stream);
    messages.push_back(bytes);
  }
  return messages;
}

std::vector<birkhoff_cart::IntegrationError> integration_errors(const std::string& path, const std::string& topic) {
  rosbag::Bag bag(path, rosbag::bagmode::Read);
  rosbag::View view(bag, rosbag::TopicQuery(std::vector<std::string>{topic}));
  std::vector<birkhoff_cart::IntegrationError> errors;
  for (const rosbag::MessageInstance& instance : view) {
    const auto error = instance.instantiate<birkhoff_cart::IntegrationError>();
    if (error) errors.push_back(*error);
  }
  return errors;
}

/// The data of every std_msgs/Float64 on `topic`, in order.
std::vector<double> command_values(const std::string& path, const std::string& topic) {
  rosbag::Bag bag(path, rosbag::bagmode::Read);
  rosbag::View view(bag, rosbag::TopicQuery(std::vector<std::string>{topic}));
  std::vector<double> values;
  for (const rosbag::MessageInstance& instance : view) {
    const auto command = instance.instantiate<std_msgs::Float64>();
    if (command) values.push_back(command->data);
  }
  return values;
}

template <class Message>
std::vector<uint8_t> serialized(const Message& message) {
  const uint32_t length = ros::serialization::serializationLength(message);
  std::vector<uint8_t> bytes(length);
  ros::serialization::OStream stream(bytes.data(), length);
  ros::serialization::serialize(stream, message);
  return bytes;
}

TEST(FaultSignals, SameSceneAndCommandsRecordIdenticalData) {
  const std::string first = recorded_run("determinism_a");
  const std::string second = recorded_run("determinism_b");
  ASSERT_TRUE(file_exists(first) && file_exists(second));
  for (const char* topic : {"/odom", "/joint_states"}) {
    const auto a = raw_messages(first, topic);
    const auto b = raw_messages(second, topic);
    ASSERT_EQ(a.size(), 200u) << topic;  // 2 s × 100 Hz
    ASSERT_EQ(a.size(), b.size()) << topic;
    for (std::size_t k = 0; k < a.size(); ++k) ASSERT_EQ(a[k], b[k]) << topic << " message " << k;
  }
  const auto a = integration_errors(first, "/determinism_a/integration_error");
  const auto b = integration_errors(second, "/determinism_b/integration_error");
  ASSERT_EQ(a.size(), 200u);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t k = 0; k < a.size(); ++k) {
    birkhoff_cart::IntegrationError left = a[k];
    birkhoff_cart::IntegrationError right = b[k];
    left.wall_time_per_step = right.wall_time_per_step = 0.0;  // the only wall-time field
    // compared as bytes: the reference-error fields are NaN without a reference, and NaN != NaN
    EXPECT_EQ(serialized(left), serialized(right)) << "integration_error " << k;
  }
  // The commands arrived, before the run started, and were recorded as received, the same in both:
  // without them both runs would be the unforced scene and identical anyway.
  for (const auto& [path, name] : {std::make_pair(first, std::string("determinism_a")),
                                   std::make_pair(second, std::string("determinism_b"))}) {
    const std::vector<double> steering = command_values(path, "/" + name + "/steering_torque");
    const std::vector<double> drive = command_values(path, "/" + name + "/drive_torque");
    EXPECT_EQ(steering, (std::vector<double>{0.4, 1.2, 0.8})) << name;
    EXPECT_EQ(drive, (std::vector<double>{25.0})) << name;
    const std::vector<double> first_odom = stamps(path, "/odom");
    ASSERT_FALSE(first_odom.empty()) << name;
    for (const char* topic : {"/steering_torque", "/drive_torque"}) {
      for (double t : stamps(path, "/" + name + topic)) {
        EXPECT_LT(t, first_odom.front()) << name << topic << " arrived after the run had started";
      }
    }
  }
  EXPECT_EQ(raw_messages(first, "/determinism_a/steering_torque"),
            raw_messages(second, "/determinism_b/steering_torque"));
  EXPECT_EQ(raw_messages(first, "/determinism_a/drive_torque"), raw_messages(second, "/determinism_b/drive_torque"));
  std::remove(first.c_str());
  std::remove(second.c_str());
}

}  // namespace

/// The children's logs, kept for the failure messages, removed at the end: tests leave nothing
/// behind in /tmp.
class RemoveScratchLogs : public testing::Environment {
 public:
  void TearDown() override {
    for (const char* name : {"sigterm.log", "sigkill.log", "unwritable.log", "negative_start.log",
                             "determinism_a.log", "determinism_b.log"}) {
      std::remove(scratch(name).c_str());
    }
  }
};

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  testing::AddGlobalTestEnvironment(new RemoveScratchLogs);
  ros::init(argc, argv, "fault_signals_test");
  ros::NodeHandle node;
  return RUN_ALL_TESTS();
}
