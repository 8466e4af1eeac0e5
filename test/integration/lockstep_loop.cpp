// rostest lockstep_loop: a closed loop through another node is the same on every run.
// cart_sim in ~lockstep mode and the example steering_pd_controller run twice (child processes,
// one pair at a time); each run records a bag with ~record_wall_time false. The two bags must be
// identical byte for byte, every publish instant must have been answered (steering_torque and
// drive_torque counts = published instants, no lockstep timeout), and the loop must be closed:
// the steering angle follows the controller's reference (the PD loop acts).
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/JointState.h>

#include "test_helpers.h"

namespace {

constexpr double kWaitTimeout = 120.0;       // [s of wall time], only against hangs
constexpr double kDuration = 10.0;           // scene time per run [s]
constexpr double kPublishRate = 50.0;        // publish instants = control instants [Hz]
constexpr double kReferenceAmplitude = 0.3;  // controller's χ_ref amplitude [rad] (its default)

using birkhoff_cart_test::file_exists;
using birkhoff_cart_test::read_file;
using birkhoff_cart_test::start_cart_sim;
using birkhoff_cart_test::start_program;
using birkhoff_cart_test::wait_exit;

/// nodelet's executable (Debian's libnodeletlib-tools).
constexpr const char* kNodeletExecutable = "/usr/lib/nodelet/nodelet";

std::string scratch(const std::string& name) { return "/tmp/lockstep_loop_" + std::to_string(::getpid()) + "_" + name; }

struct LoopRun {
  int status = -1;
  std::string bag;
  std::string summary;
  std::string log;
};

LoopRun run_loop(const std::string& label) {
  std::string scene;
  ros::NodeHandle("~").getParam("scene", scene);
  LoopRun run;
  run.bag = scratch(label + ".bag");
  const std::string summary_path = scratch(label + "_summary.txt");
  const std::string controller_log = scratch(label + "_controller.log");
  const std::string sim_log = scratch(label + "_sim.log");
  const pid_t controller = start_program("steering_pd_controller", {"__name:=pd_" + label}, controller_log);
  const pid_t simulator = start_cart_sim({"__name:=lockstep_sim", "_scene:=" + scene, "_fast:=true",
                                          "_lockstep:=true", "_duration:=" + std::to_string(kDuration),
                                          "_publish_rate:=" + std::to_string(kPublishRate),
                                          "_bag_path:=" + run.bag, "_record_wall_time:=false",
                                          "_summary_path:=" + summary_path},
                                         sim_log);
  run.status = wait_exit(simulator, kWaitTimeout);
  ::kill(controller, SIGINT);
  wait_exit(controller, 10.0);
  run.summary = read_file(summary_path);
  run.log = read_file(sim_log) + read_file(controller_log);
  for (const std::string& path : {summary_path, controller_log, sim_log}) std::remove(path.c_str());
  ros::NodeHandle().deleteParam("/lockstep_sim");
  ros::NodeHandle().deleteParam("/pd_" + label);
  return run;
}

/// The same loop as nodelets in one manager (docs/ros_interface.md, "Nodelets"): cart_sim and
/// steering_pd_controller exchange shared messages without serialization.
LoopRun run_nodelet_loop(const std::string& label) {
  std::string scene;
  ros::NodeHandle("~").getParam("scene", scene);
  LoopRun run;
  run.bag = scratch(label + ".bag");
  const std::string summary_path = scratch(label + "_summary.txt");
  const std::string manager_log = scratch(label + "_manager.log");
  const std::string manager = "loop_manager_" + label;
  ros::NodeHandle parameters("/lockstep_sim");
  parameters.setParam("scene", scene);
  parameters.setParam("fast", true);
  parameters.setParam("lockstep", true);
  parameters.setParam("duration", kDuration);
  parameters.setParam("publish_rate", kPublishRate);
  parameters.setParam("bag_path", run.bag);
  parameters.setParam("record_wall_time", false);
  parameters.setParam("summary_path", summary_path);
  const pid_t manager_pid = start_program(kNodeletExecutable, {"manager", "__name:=" + manager}, manager_log);
  const pid_t controller = start_program(kNodeletExecutable, {"load", "birkhoff_cart/SteeringPdController", manager,
                                                              "__name:=pd_" + label});
  const pid_t simulator = start_program(kNodeletExecutable, {"load", "birkhoff_cart/CartSim", manager,
                                                             "__name:=lockstep_sim"});
  // The run ends inside the manager: its summary file appears after the bag is closed.
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(kWaitTimeout);
  while (ros::WallTime::now() < deadline && read_file(summary_path).find("Lockstep timeouts") == std::string::npos) {
    ros::WallDuration(0.05).sleep();
  }
  run.summary = read_file(summary_path);
  run.status = run.summary.empty() ? -1 : 0;
  for (const pid_t pid : {simulator, controller, manager_pid}) {
    ::kill(pid, SIGINT);
    wait_exit(pid, 10.0);
  }
  run.log = read_file(manager_log);
  for (const std::string& path : {summary_path, manager_log}) std::remove(path.c_str());
  ros::NodeHandle().deleteParam("/lockstep_sim");
  ros::NodeHandle().deleteParam("/pd_" + label);
  return run;
}

std::size_t count(const std::string& bag_path, const std::string& topic) {
  rosbag::Bag bag(bag_path, rosbag::bagmode::Read);
  return rosbag::View(bag, rosbag::TopicQuery(std::vector<std::string>{topic})).size();
}

TEST(LockstepLoop, TwoRunsRecordIdenticalBags) {
  const LoopRun first = run_loop("first");
  const LoopRun second = run_loop("second");
  ASSERT_EQ(first.status, 0) << first.log;
  ASSERT_EQ(second.status, 0) << second.log;
  ASSERT_TRUE(file_exists(first.bag)) << first.log;
  ASSERT_TRUE(file_exists(second.bag)) << second.log;
  const std::string first_bytes = read_file(first.bag);
  const std::string second_bytes = read_file(second.bag);
  EXPECT_GT(first_bytes.size(), 0u);
  EXPECT_TRUE(first_bytes == second_bytes) << "the two lockstep runs recorded different bags ("
                                           << first_bytes.size() << " and " << second_bytes.size() << " bytes)";

  // Every instant answered, no timeout.
  const std::size_t instants = static_cast<std::size_t>(std::lround(kDuration * kPublishRate));
  EXPECT_EQ(count(first.bag, "/joint_states"), instants);
  EXPECT_EQ(count(first.bag, "/steering_torque"), instants);
  EXPECT_EQ(count(first.bag, "/drive_torque"), instants);
  EXPECT_NE(first.summary.find("Lockstep timeouts: 0."), std::string::npos) << first.summary;

  // The loop acts: χ reaches a good part of the reference amplitude (without the controller the
  // steering stays at 0 on driven.yaml, which holds τ = 0 until commanded).
  double largest_angle = 0.0;
  {
    rosbag::Bag bag(first.bag, rosbag::bagmode::Read);
    for (const rosbag::MessageInstance& instance :
         rosbag::View(bag, rosbag::TopicQuery(std::vector<std::string>{"/joint_states"}))) {
      const auto joints = instance.instantiate<sensor_msgs::JointState>();
      largest_angle = std::max(largest_angle, std::abs(joints->position.at(0)));
    }
  }
  EXPECT_GT(largest_angle, 0.5 * kReferenceAmplitude);
  const std::size_t factor_at = first.summary.find("real-time factor ");
  std::printf("[ measured ] lockstep loop, %g s of scene time at %g Hz: largest |chi| %.4f rad; %s\n", kDuration,
              kPublishRate, largest_angle,
              factor_at == std::string::npos ? "no summary" : first.summary.substr(factor_at, 40).c_str());
  std::remove(first.bag.c_str());
  std::remove(second.bag.c_str());
}

TEST(LockstepLoop, NodeletLoopsRecordTheSeparateNodesBag) {
  const LoopRun nodes = run_loop("nodes");
  const LoopRun first = run_nodelet_loop("nodelets_first");
  const LoopRun second = run_nodelet_loop("nodelets_second");
  ASSERT_EQ(nodes.status, 0) << nodes.log;
  ASSERT_EQ(first.status, 0) << first.log;
  ASSERT_EQ(second.status, 0) << second.log;
  ASSERT_TRUE(file_exists(first.bag)) << first.log;
  const std::string node_bytes = read_file(nodes.bag);
  const std::string first_bytes = read_file(first.bag);
  const std::string second_bytes = read_file(second.bag);
  EXPECT_GT(first_bytes.size(), 0u);
  EXPECT_TRUE(first_bytes == second_bytes) << "two nodelet loops recorded different bags";
  EXPECT_TRUE(first_bytes == node_bytes) << "the nodelet loop's bag differs from the separate nodes' ("
                                         << first_bytes.size() << " and " << node_bytes.size() << " bytes)";
  EXPECT_NE(first.summary.find("Lockstep timeouts: 0."), std::string::npos) << first.summary;
  const std::size_t nodelet_factor = first.summary.find("real-time factor ");
  const std::size_t node_factor = nodes.summary.find("real-time factor ");
  std::printf("[ measured ] lockstep loop, %g s at %g Hz: separate nodes %s; nodelets %s\n", kDuration, kPublishRate,
              node_factor == std::string::npos ? "no summary" : nodes.summary.substr(node_factor, 40).c_str(),
              nodelet_factor == std::string::npos ? "no summary" : first.summary.substr(nodelet_factor, 40).c_str());
  for (const LoopRun* run : {&nodes, &first, &second}) std::remove(run->bag.c_str());
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "lockstep_loop");
  ros::NodeHandle node;
  return RUN_ALL_TESTS();
}
