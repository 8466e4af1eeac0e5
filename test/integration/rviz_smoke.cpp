// rostest rviz_smoke: rviz with rviz/cart.rviz (RobotModel from robot_description, TF, Odometry)
// starts under Xvfb and keeps running without logging an error, while cart_sim and
// robot_state_publisher feed it. Debian's rviz logs "no such package media_export" (harmless): ignored.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <sstream>
#include <string>

#include <ros/ros.h>

namespace {

constexpr int kTimeoutExitStatus = 124;  // `timeout` killed rviz: it was still running

TEST(RvizSmoke, StartsWithTheCartConfigAndLogsNoError) {
  ros::NodeHandle private_node("~");
  std::string config;
  double seconds = 8.0;
  ASSERT_TRUE(private_node.getParam("rviz_config", config));
  private_node.getParam("seconds", seconds);
  const std::string command = "timeout -s INT " + std::to_string(seconds) +
                              " xvfb-run -a -s '-screen 0 1024x768x24' rviz -d " + config + " 2>&1";
  FILE* pipe = ::popen(command.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string output;
  std::array<char, 1024> buffer;
  while (std::fgets(buffer.data(), buffer.size(), pipe)) output += buffer.data();
  const int status = ::pclose(pipe);
  ASSERT_TRUE(WIFEXITED(status)) << output;
  EXPECT_EQ(WEXITSTATUS(status), kTimeoutExitStatus) << "rviz exited early:\n" << output;

  std::istringstream lines(output);
  std::string line;
  int errors = 0;
  while (std::getline(lines, line)) {
    const bool error = line.find("ERROR") != std::string::npos || line.find("FATAL") != std::string::npos ||
                       line.find("Segmentation fault") != std::string::npos;
    if (error && line.find("media_export") == std::string::npos) {
      ADD_FAILURE() << "rviz: " << line;
      ++errors;
    }
  }
  EXPECT_EQ(errors, 0) << output;
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "rviz_smoke_test");
  ros::NodeHandle node;
  return RUN_ALL_TESTS();
}
