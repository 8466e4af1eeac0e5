// rostest fault_flood: 1e5 steering commands at 10 kHz for 10 s against cart_sim in real-time mode
// (docs/hard_cases.md §10). One in four is NaN or ±Inf (rejected), one in four is ±1e300 (clamped),
// the rest valid. Checked: the node's /diagnostics counters account for what it received
// (received ≤ sent, rejected and clamped > 0), its resident memory grows by less than
// kMemoryGrowthLimit, scene time keeps pace with the wall clock during the flood, the node
// keeps running and stops cleanly (exit 0) with a complete bag. The hold rule itself ("the latest
// valid command wins") is proven without a master in test/unit/bad_input_test.cpp and
// test/ros_unit/command_channel_test.cpp.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include <diagnostic_msgs/DiagnosticArray.h>
#include <ros/ros.h>
#include <std_msgs/Float64.h>

#include "test_helpers.h"

namespace {

constexpr double kWaitTimeout = 60.0;            // [s of wall time], only against hangs
constexpr double kFloodRate = 10000.0;           // [Hz of wall time]
constexpr double kFloodDuration = 10.0;          // [s of wall time]
constexpr long kMemoryGrowthLimit = 16 * 1024;   // RSS growth over the flood [kB]
constexpr double kMinimumPace = 0.8;             // scene seconds per wall second during the flood [-]

using birkhoff_cart_test::start_cart_sim;
using birkhoff_cart_test::wait_exit;

bool alive(pid_t pid) { return ::waitpid(pid, nullptr, WNOHANG) == 0; }

/// VmRSS of process `pid` [kB] (−1 when unreadable).
long resident_kilobytes(pid_t pid) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("VmRSS:", 0) == 0) return std::stol(line.substr(6));
  }
  return -1;
}

TEST(FaultFlood, CommandsAtTenKilohertzAreCountedMemoryAndPaceKept) {
  ros::NodeHandle node;
  std::string scene;
  ASSERT_TRUE(ros::NodeHandle("~").getParam("scene", scene));
  const std::string bag_path = "/tmp/fault_flood_" + std::to_string(::getpid()) + ".bag";
  const pid_t pid = start_cart_sim({"__name:=flood_sim", "_scene:=" + scene, "_bag_path:=" + bag_path,
                                    "_fast:=false", "_duration:=0.0", "_command_timeout:=0.0",
                                    "_diagnostic_period:=0.5"});
  ASSERT_GT(pid, 0);

  std::map<std::string, std::string> last_status;  // key → value of the latest cart_sim status
  ros::Subscriber diagnostics = node.subscribe<diagnostic_msgs::DiagnosticArray>(
      "/diagnostics", 10, [&](const diagnostic_msgs::DiagnosticArray::ConstPtr& array) {
        for (const auto& status : array->status) {
          if (status.name.find("simulation") == std::string::npos) continue;
          last_status.clear();
          for (const auto& pair : status.values) last_status[pair.key] = pair.value;
        }
      });
  ros::Publisher steering = node.advertise<std_msgs::Float64>("steering_torque", 100);
  ASSERT_TRUE(birkhoff_cart_test::wait_for([&] { return steering.getNumSubscribers() > 0; }, kWaitTimeout));
  ASSERT_TRUE(birkhoff_cart_test::wait_for([&] { return ros::Time::now().toSec() > 1.0; }, kWaitTimeout));
  const long resident_before = resident_kilobytes(pid);
  const double scene_before = ros::Time::now().toSec();
  const ros::WallTime wall_before = ros::WallTime::now();

  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  long sent = 0;
  ros::WallRate rate(kFloodRate);
  const long total = static_cast<long>(kFloodRate * kFloodDuration);
  for (long n = 0; n < total && ros::ok(); ++n) {
    std_msgs::Float64 message;
    switch (n % 4) {
      case 0: message.data = n % 8 == 0 ? nan : (n % 3 ? inf : -inf); break;       // rejected
      case 1: message.data = n % 2 ? 1e300 : -1e300; break;                         // clamped
      default: message.data = 2.0 * std::sin(1e-3 * static_cast<double>(n)); break; // valid
    }
    steering.publish(message);
    ++sent;
    if (n % 100 == 0) ros::spinOnce();
    rate.sleep();
  }
  ros::spinOnce();  // the latest /clock
  const double wall_elapsed = (ros::WallTime::now() - wall_before).toSec();
  const double scene_elapsed = ros::Time::now().toSec() - scene_before;
  ros::WallDuration(1.0).sleep();  // the last diagnostics period after the flood
  ros::spinOnce();
  const long resident_after = resident_kilobytes(pid);
  ASSERT_TRUE(alive(pid)) << "cart_sim died during the flood";
  ASSERT_TRUE(birkhoff_cart_test::wait_for([&] { return !last_status.empty(); }, kWaitTimeout));

  const long received = std::stol(last_status["steering_torque commands received"]);
  const long rejected = std::stol(last_status["steering_torque commands rejected"]);
  const long clamped = std::stol(last_status["steering_torque commands clamped"]);
  EXPECT_LE(received, sent);
  EXPECT_GT(received, sent / 10) << "the node should see most of the flood";
  EXPECT_GT(rejected, 0);
  EXPECT_GT(clamped, 0);
  EXPECT_LE(rejected + clamped, received);
  EXPECT_LE(resident_after - resident_before, kMemoryGrowthLimit);
  EXPECT_GT(scene_elapsed / wall_elapsed, kMinimumPace) << "scene " << scene_elapsed << " s in " << wall_elapsed << " s";
  std::printf("[ measured ] flood: sent %ld in %.2f s, received %ld, rejected %ld, clamped %ld; RSS %ld -> %ld kB; "
              "scene time %.2f s (pace %.3f)\n",
              sent, wall_elapsed, received, rejected, clamped, resident_before, resident_after, scene_elapsed,
              scene_elapsed / wall_elapsed);

  ASSERT_EQ(::kill(pid, SIGINT), 0);
  EXPECT_EQ(wait_exit(pid, 30.0), 0);
  struct stat info;
  EXPECT_EQ(::stat(bag_path.c_str(), &info), 0) << "no closed bag at " << bag_path;
  std::remove(bag_path.c_str());
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "fault_flood_test");
  ros::NodeHandle node;
  return RUN_ALL_TESTS();
}
