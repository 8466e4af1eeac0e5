// rostest node_exits: exits and records.
//  - INFO lines reach a log file while the node runs (stdout was fully buffered into a file, so
//    they appeared only at exit).
//  - The summary's real-time factor is scene time over the wall time *not paused*.
//  - A scene whose times reach ROS time's end (2^32 s) is refused at start with exit 2, by name
//    (it aborted in ros::Time with the bag unfinished).
//  - A ~position_tolerance on a run at fixed steps (no ~step_control, none in the scene) is refused
//    at start with exit 2, by name (it was silently ignored).
//  - A ~reset while recording closes the run's bag and records the next run to <stem>_run2.bag:
//    no bag holds the overlapping times of two runs.
//  - sim.launch record:=false sets ~bag_path to "" (a ~bag_path left on the master by an earlier
//    run recorded again and overwrote that earlier bag).
#include <gtest/gtest.h>

#include <signal.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <regex>
#include <string>
#include <vector>

#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <std_srvs/Empty.h>

#include "test_helpers.h"

namespace {

constexpr double kWaitTimeout = 60.0;  // [s of wall time], only against hangs

using birkhoff_cart_test::file_exists;
using birkhoff_cart_test::read_file;
using birkhoff_cart_test::run_command;
using birkhoff_cart_test::set_paused;
using birkhoff_cart_test::start_cart_sim;
using birkhoff_cart_test::wait_exit;
using birkhoff_cart_test::wait_for;

std::string scene_parameter() {
  std::string scene;
  ros::NodeHandle("~").getParam("scene", scene);
  return scene;
}

std::string scratch(const std::string& name) { return "/tmp/node_exits_" + std::to_string(::getpid()) + "_" + name; }

bool alive(pid_t pid) { return ::kill(pid, 0) == 0; }

TEST(NodeExits, InfoLinesReachALogFileWhileTheNodeRuns) {
  const std::string log = scratch("flush.log");
  const pid_t pid = start_cart_sim({"__name:=exits_flush", "_scene:=" + scene_parameter(), "_start_paused:=true",
                                    "_duration:=0"},
                                   log);
  ASSERT_GT(pid, 0);
  // The start-up INFO line must be in the file while the node still runs (it waits, paused).
  const bool seen = wait_for([&] { return read_file(log).find("cart_sim: scene") != std::string::npos; }, kWaitTimeout);
  EXPECT_TRUE(alive(pid));
  ::kill(pid, SIGINT);
  EXPECT_EQ(wait_exit(pid, 30.0), 0) << read_file(log);
  EXPECT_TRUE(seen) << "the INFO line appeared only at exit: " << read_file(log);
  std::remove(log.c_str());
  ros::NodeHandle().deleteParam("/exits_flush");
}

TEST(NodeExits, RealTimeFactorLeavesOutPausedTime) {
  const std::string log = scratch("pause.log");
  const std::string summary_path = scratch("pause_summary.txt");
  const pid_t pid = start_cart_sim({"__name:=exits_pause", "_scene:=" + scene_parameter(), "_start_paused:=true",
                                    "_fast:=true", "_duration:=20", "_summary_path:=" + summary_path},
                                   log);
  ASSERT_GT(pid, 0);
  ASSERT_TRUE(wait_for([&] { return ros::service::exists("/exits_pause/pause", false); }, kWaitTimeout));
  ros::WallDuration(1.5).sleep();  // paused: at least 1 s of wall time that must not count
  ASSERT_TRUE(set_paused("/exits_pause/pause", false));
  EXPECT_EQ(wait_exit(pid, kWaitTimeout), 0) << read_file(log);
  const std::string summary = read_file(summary_path);
  std::smatch match;
  ASSERT_TRUE(std::regex_search(summary, match,
                                std::regex(R"(wall time ([0-9.e+-]+) s \(stepping [0-9.e+-]+ s, paused ([0-9.e+-]+) s\), real-time factor ([0-9.e+-]+))")))
      << summary;
  const double wall = std::stod(match[1]);
  const double paused = std::stod(match[2]);
  const double factor = std::stod(match[3]);
  EXPECT_GE(paused, 1.0) << summary;
  EXPECT_LT(paused, wall) << summary;
  // 20 s of scene time over the running (not paused) wall time, to the summary's 9 digits and the
  // few microseconds between the two clock readings.
  EXPECT_NEAR(factor, 20.0 / (wall - paused), 1e-3 * factor) << summary;
  EXPECT_GT(factor, 20.0 / wall) << summary;
  std::remove(log.c_str());
  std::remove(summary_path.c_str());
  ros::NodeHandle().deleteParam("/exits_pause");
}

TEST(NodeExits, SceneTimesBeyondRosTimeAreRefusedByName) {
  std::string text = read_file(scene_parameter());
  const std::string start = "  time: 0.0 ";
  const std::size_t at = text.find(start);
  ASSERT_NE(at, std::string::npos) << "driven.yaml no longer starts with '  time: 0.0 '";
  text.replace(at, start.size(), "  time: 4294967290.0 ");  // 5 s before ROS time ends; the run lasts 60 s
  // A step coarse enough for the scene loader's precision rule there (h >= 0.5 s), so the ROS-time
  // limit is the one that refuses the run.
  const std::size_t step_at = text.find("step_size: 1.0e-3");
  ASSERT_NE(step_at, std::string::npos) << "driven.yaml no longer has 'step_size: 1.0e-3'";
  text.replace(step_at, std::string("step_size: 1.0e-3").size(), "step_size: 1.0");
  const std::string scene = scratch("late_start.yaml");
  const std::string bag = scratch("late_start.bag");
  const std::string log = scratch("late_start.log");
  std::ofstream(scene) << text;
  const pid_t pid =
      start_cart_sim({"__name:=exits_late", "_scene:=" + scene, "_fast:=true", "_bag_path:=" + bag}, log);
  ASSERT_GT(pid, 0);
  const int status = wait_exit(pid, kWaitTimeout);
  const std::string output = read_file(log);
  EXPECT_EQ(status, 2) << output;
  EXPECT_NE(output.find("2^32"), std::string::npos) << output;
  EXPECT_FALSE(file_exists(bag) || file_exists(bag + ".active")) << "a refused node opened its bag";
  for (const std::string& path : {scene, log, bag, bag + ".active"}) std::remove(path.c_str());
  ros::NodeHandle().deleteParam("/exits_late");
}

TEST(NodeExits, APositionToleranceWithoutAStepControlIsRefusedByName) {
  const std::string bag = scratch("no_control.bag");
  const std::string log = scratch("no_control.log");
  const pid_t pid = start_cart_sim(
      {"__name:=exits_no_control", "_scene:=" + scene_parameter(), "_fast:=true", "_position_tolerance:=1e-6",
       "_bag_path:=" + bag},
      log);
  ASSERT_GT(pid, 0);
  const int status = wait_exit(pid, kWaitTimeout);
  const std::string output = read_file(log);
  EXPECT_EQ(status, 2) << output;
  EXPECT_NE(output.find("~position_tolerance"), std::string::npos) << output;
  EXPECT_NE(output.find("~step_control"), std::string::npos) << output;
  EXPECT_FALSE(file_exists(bag) || file_exists(bag + ".active")) << "a refused node opened its bag";
  for (const std::string& path : {log, bag, bag + ".active"}) std::remove(path.c_str());
  ros::NodeHandle().deleteParam("/exits_no_control");
}

/// Odometry stamps of a bag, in bag order [s].
std::vector<double> odom_stamps(const std::string& path) {
  rosbag::Bag bag(path, rosbag::bagmode::Read);
  std::vector<double> stamps;
  for (const rosbag::MessageInstance& instance :
       rosbag::View(bag, rosbag::TopicQuery(std::vector<std::string>{"/odom"}))) {
    stamps.push_back(instance.getTime().toSec());
  }
  return stamps;
}

TEST(NodeExits, EachRunAfterAResetIsRecordedToItsOwnBag) {
  const std::string bag = scratch("runs.bag");
  const std::string second_bag = scratch("runs_run2.bag");
  const std::string log = scratch("runs.log");
  double latest = 0.0;
  ros::NodeHandle node;
  ros::Subscriber odometry = node.subscribe<nav_msgs::Odometry>(
      "/odom", 100, [&](const nav_msgs::Odometry::ConstPtr& message) { latest = message->header.stamp.toSec(); });
  const pid_t pid = start_cart_sim({"__name:=exits_runs", "_scene:=" + scene_parameter(), "_fast:=true",
                                    "_real_time_factor:=4", "_duration:=0", "_bag_path:=" + bag},
                                   log);
  ASSERT_GT(pid, 0);
  ASSERT_TRUE(wait_for([&] { return latest > 1.0; }, kWaitTimeout)) << read_file(log);
  std_srvs::Empty reset;
  ASSERT_TRUE(ros::service::call("/exits_runs/reset", reset));
  ASSERT_TRUE(wait_for([&] { return latest > 0.0 && latest < 0.5; }, kWaitTimeout)) << "no reset seen";
  ASSERT_TRUE(wait_for([&] { return latest > 0.5; }, kWaitTimeout));
  ::kill(pid, SIGINT);
  EXPECT_EQ(wait_exit(pid, 30.0), 0) << read_file(log);
  ASSERT_TRUE(file_exists(bag)) << read_file(log);
  ASSERT_TRUE(file_exists(second_bag)) << read_file(log);
  for (const std::string& path : {bag, second_bag}) {
    const std::vector<double> stamps = odom_stamps(path);
    ASSERT_FALSE(stamps.empty()) << path;
    for (std::size_t k = 1; k < stamps.size(); ++k) {
      ASSERT_LT(stamps[k - 1], stamps[k]) << path << ": times of two runs in one bag at message " << k;
    }
  }
  EXPECT_GT(odom_stamps(bag).back(), 1.0);
  EXPECT_LT(odom_stamps(second_bag).front(), 0.5);
  for (const std::string& path : {bag, second_bag, log}) std::remove(path.c_str());
  ros::NodeHandle().deleteParam("/exits_runs");
}

TEST(NodeExits, SimLaunchWithoutRecordClearsAStaleBagPath) {
  std::string output;
  ASSERT_EQ(run_command("roslaunch --dump-params birkhoff_cart sim.launch record:=false", &output), 0) << output;
  EXPECT_NE(output.find("/cart_sim/bag_path: ''"), std::string::npos)
      << "record:=false must set ~bag_path to \"\" explicitly: " << output;
  output.clear();
  ASSERT_EQ(run_command("roslaunch --dump-params birkhoff_cart sim.launch record:=true bag_path:=/tmp/x.bag", &output),
            0)
      << output;
  EXPECT_NE(output.find("/cart_sim/bag_path: /tmp/x.bag"), std::string::npos) << output;
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "node_exits");
  ros::NodeHandle node;
  return RUN_ALL_TESTS();
}
