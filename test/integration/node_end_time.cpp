// rostest node_end_time: one rule for how a run is cut into steps. cart_sim
// stopped at the first step with t + h/2 > t0 + T: a duration off the step grid ended up to half a
// step late (0.0105 s at h = 1 ms ended at 0.011 s), its last published instant was before the end,
// and the state differed from cart_simulate's. Now both take whole steps onto t0 + n h and one
// landing step onto t0 + T: the node's final time is t0 + T exactly, its last published instant is
// t0 + T, and its final joint positions and steering rate are cart_simulate's last row, bit for bit.
#include <gtest/gtest.h>

#include <unistd.h>

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

#include "birkhoff_cart/ros/conversions.h"
#include "test_helpers.h"

namespace {

constexpr double kWaitTimeout = 60.0;  // [s of wall time], only against hangs

using birkhoff_cart_test::package_executable;
using birkhoff_cart_test::read_file;
using birkhoff_cart_test::run_command;
using birkhoff_cart_test::start_cart_sim;
using birkhoff_cart_test::wait_exit;

std::string scene_parameter() {
  std::string scene;
  ros::NodeHandle("~").getParam("scene", scene);
  return scene;
}

std::string scratch(const std::string& name) {
  return "/tmp/node_end_time_" + std::to_string(::getpid()) + "_" + name;
}

/// The scene text with `old_text` replaced by `new_text` (which must be there).
std::string edited(std::string text, const std::string& old_text, const std::string& new_text) {
  const std::size_t at = text.find(old_text);
  EXPECT_NE(at, std::string::npos) << "the scene no longer has '" << old_text << "'";
  if (at != std::string::npos) text.replace(at, old_text.size(), new_text);
  return text;
}

/// The fields of the last line of a CSV file, as doubles (strtod reads %.17g back exactly).
std::vector<double> last_row(const std::string& path) {
  std::ifstream file(path);
  std::string line, last;
  while (std::getline(file, line)) {
    if (!line.empty()) last = line;
  }
  std::vector<double> fields;
  std::stringstream row(last);
  std::string field;
  while (std::getline(row, field, ',')) fields.push_back(field.empty() ? 0.0 : std::stod(field));
  return fields;
}

/// The number after `key` in the summary (read back exactly: the node prints final t exactly).
double summary_number(const std::string& summary, const std::string& key) {
  const std::size_t at = summary.find(key);
  if (at == std::string::npos) return -1.0;
  return std::stod(summary.substr(at + key.size()));
}

template <typename Message>
std::vector<Message> bag_messages(const std::string& path, const std::string& topic) {
  rosbag::Bag bag(path, rosbag::bagmode::Read);
  std::vector<Message> messages;
  for (const rosbag::MessageInstance& instance : rosbag::View(bag, rosbag::TopicQuery(topic))) {
    if (const auto message = instance.instantiate<Message>()) messages.push_back(*message);
  }
  return messages;
}

/// Runs cart_sim (fast, recording) and cart_simulate on `scene_text` with the extra node and CLI
/// arguments, and checks that both end at `end_time` exactly and in the same state.
void expect_both_end_at(const std::string& name, const std::string& scene_text,
                        const std::vector<std::string>& node_arguments, const std::string& cli_arguments,
                        double end_time) {
  const std::string scene = scratch(name + ".yaml");
  const std::string bag = scratch(name + ".bag");
  const std::string summary_path = scratch(name + "_summary.txt");
  const std::string log = scratch(name + ".log");
  const std::string csv = scratch(name + ".csv");
  std::ofstream(scene) << scene_text;

  std::vector<std::string> arguments = {"__name:=end_" + name, "_scene:=" + scene, "_fast:=true",
                                        "_bag_path:=" + bag, "_summary_path:=" + summary_path};
  arguments.insert(arguments.end(), node_arguments.begin(), node_arguments.end());
  const pid_t pid = start_cart_sim(arguments, log);
  ASSERT_GT(pid, 0);
  ASSERT_EQ(wait_exit(pid, kWaitTimeout), 0) << read_file(log);
  std::string output;
  ASSERT_EQ(run_command(package_executable("cart_simulate") + " --quiet --scene " + scene + " --output " + csv + " " +
                            cli_arguments,
                        &output),
            0)
      << output;

  // The node's final time, read back from its summary: t0 + T exactly, not the next step.
  const std::string summary = read_file(summary_path);
  EXPECT_EQ(summary_number(summary, "final t = "), end_time) << summary;
  // Its last published instant is the end (stamps to the nanosecond), and none lies beyond it.
  const std::vector<sensor_msgs::JointState> joints = bag_messages<sensor_msgs::JointState>(bag, "/joint_states");
  const std::vector<nav_msgs::Odometry> odometry = bag_messages<nav_msgs::Odometry>(bag, "/odom");
  ASSERT_FALSE(joints.empty()) << read_file(log);
  ASSERT_FALSE(odometry.empty()) << read_file(log);
  const ros::Time end_stamp = birkhoff_cart::ros_conversions::to_ros_time(end_time);
  EXPECT_EQ(joints.back().header.stamp, end_stamp);
  EXPECT_EQ(odometry.back().header.stamp, end_stamp);
  for (std::size_t k = 1; k < odometry.size(); ++k) {
    ASSERT_LT(odometry[k - 1].header.stamp, odometry[k].header.stamp) << "message " << k;
  }

  // cart_simulate's last row: t,x,y,theta,chi,phi1..phi4,pi1,omega1,omega2,...
  const std::vector<double> row = last_row(csv);
  ASSERT_GE(row.size(), 12u) << read_file(csv);
  EXPECT_EQ(row[0], end_time);
  // The same steps in both: joint positions (χ, φ1..φ4) and the steering rate ω2, bit for bit.
  ASSERT_EQ(joints.back().position.size(), 5u);
  for (std::size_t joint = 0; joint < 5; ++joint) {
    EXPECT_EQ(joints.back().position[joint], row[4 + joint]) << "joint " << joints.back().name[joint];
  }
  EXPECT_EQ(joints.back().velocity[0], row[11]) << "steering rate";

  for (const std::string& path : {scene, bag, summary_path, log, csv}) std::remove(path.c_str());
  ros::NodeHandle().deleteParam("/end_" + name);
}

TEST(NodeEndTime, SceneDurationOffTheStepGridEndsExactlyAtTheEnd) {
  // 0.0105 s at h = 1 ms: ten whole steps and a half step; the old rule stepped on to 0.011 s.
  const std::string text = edited(read_file(scene_parameter()), "duration: 5.0 ", "duration: 0.0105 ");
  expect_both_end_at("scene_duration", text, {}, "", 0.0105);
}

TEST(NodeEndTime, DurationParameterWithinASliverOfTheGridEndsExactlyAtTheEnd) {
  // From t0 = 1 s, 4.6960000000005 s at h = 1 ms: the end lies 5e-13 s past the grid point 5.696 s
  // (where cart_simulate and the node once disagreed). The last step, from
  // 5.695 s, lands on 5.6960000000005 s.
  const std::string text = edited(read_file(scene_parameter()), "  time: 0.0 ", "  time: 1.0 ");
  const std::string duration = "4.6960000000005";
  expect_both_end_at("duration_parameter", text, {"_duration:=" + duration}, "--duration " + duration,
                     1.0 + std::stod(duration));
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "node_end_time");
  ros::NodeHandle node;
  return RUN_ALL_TESTS();
}
