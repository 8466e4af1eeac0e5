// rostest node_mains: no exception escapes main of any executable.
// ros::init, NodeHandle, advertise and subscribe throw ros::InvalidNameException for a node name,
// namespace or remapping roscpp refuses; every node let it escape main (std::terminate, exit 134,
// no line of its own). steering_driver's timer threw std::runtime_error for ~rate 1e-12 Hz (a
// period beyond ros::Duration's 2^31 s). Each must now end with exit 2 and a line naming the problem.
// A parameter of the wrong type names the type it must have and what it got. cart_sim takes a step
// control and a position tolerance as parameters.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdio>
#include <string>
#include <vector>

#include <ros/ros.h>

#include "test_helpers.h"

namespace {

using birkhoff_cart_test::package_executable;
using birkhoff_cart_test::run_command;

const std::vector<std::string> kNodes = {"cart_sim", "cmd_vel_controller", "steering_driver",
                                         "steering_pd_controller"};

/// Runs the package's `node` with `arguments` (shell-quoted here) and returns its exit status.
int run_node(const std::string& node, const std::string& arguments, std::string* output) {
  return run_command("timeout 60 " + package_executable(node) + " " + arguments, output);
}

TEST(NodeMains, EveryNodeRefusesAnInvalidNameWithExit2) {
  // A bad node name, a bad namespace, a remapping to a bad name: each refused in ros::init.
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"'__name:=9cart'", "9cart"}, {"'__ns:=/a!b'", "/a!b"}, {"'joint_states:=a!b'", "a!b"}};
  for (const std::string& node : kNodes) {
    for (const auto& [arguments, bad_name] : cases) {
      std::string output;
      const int status = run_node(node, arguments, &output);
      EXPECT_EQ(status, 2) << node << " " << arguments << ":\n" << output;
      EXPECT_NE(output.find(node + ": refused at start"), std::string::npos) << node << " " << arguments << ":\n"
                                                                              << output;
      EXPECT_NE(output.find(bad_name), std::string::npos) << output;
      EXPECT_EQ(output.find("terminate called"), std::string::npos) << output;
    }
  }
}

TEST(SteeringDriver, RefusesARateItsTimerCannotHold) {
  for (const std::string& rate : {"1e-12", "inf", "1e9", "0"}) {
    std::string output;
    const int status = run_node("steering_driver", "__name:=driver_rate _rate:=" + rate, &output);
    EXPECT_EQ(status, 2) << "~rate " << rate << ":\n" << output;
    EXPECT_NE(output.find("~rate must be in"), std::string::npos) << output;
    EXPECT_EQ(output.find("terminate called"), std::string::npos) << output;
    ros::NodeHandle().deleteParam("/driver_rate");
  }
}

TEST(CartSim, NamesTheTypeAParameterMustHave) {
  // Regression: `_fast:=1` (an int) said only "has the wrong type".
  const std::string scene = std::string(BIRKHOFF_CART_SOURCE_DIR) + "/config/scenes/default.yaml";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"_fast:=1", "parameter /typed_sim/fast must be a bool (true or false), got the int 1"},
      {"_lockstep:=yes", "parameter /typed_sim/lockstep must be a bool (true or false), got the string 'yes'"},
      {"_integrator:=4", "parameter /typed_sim/integrator must be a string, got the int 4"},
      {"_publish_rate:=fast", "parameter /typed_sim/publish_rate must be a number, got the string 'fast'"}};
  for (const auto& [argument, expected] : cases) {
    std::string output;
    const int status = run_node("cart_sim", "__name:=typed_sim _scene:=" + scene + " " + argument, &output);
    EXPECT_EQ(status, 2) << argument << ":\n" << output;
    EXPECT_NE(output.find(expected), std::string::npos) << argument << ":\n" << output;
    ros::NodeHandle().deleteParam("/typed_sim");
  }
}

TEST(CartSim, TakesAStepControlAndAPositionTolerance) {
  // ~step_control and ~position_tolerance override the scene's (docs/ros_interface.md): refused by
  // name when unknown or incomplete, and a run under the adaptive control says so in its summary.
  const std::string scene = std::string(BIRKHOFF_CART_SOURCE_DIR) + "/config/scenes/default.yaml";
  const std::vector<std::pair<std::string, std::string>> refused = {
      {"_step_control:=adaptve",
       "~step_control: unknown step_control 'adaptve' (known: fixed, reversible, adaptive; did you mean 'adaptive'?)"},
      {"_step_control:=adaptive", "position_tolerance"},
      {"_step_control:=adaptive _position_tolerance:=-1", "~position_tolerance must be >= 0 m"},
      {"_step_control:=reversible _position_tolerance:=1e-6", "reversible"}};  // the default scene's loads vary in time
  for (const auto& [arguments, expected] : refused) {
    std::string output;
    const int status = run_node("cart_sim", "__name:=controlled_sim _scene:=" + scene + " " + arguments, &output);
    EXPECT_EQ(status, 2) << arguments << ":\n" << output;
    EXPECT_NE(output.find(expected), std::string::npos) << arguments << ":\n" << output;
    EXPECT_EQ(output.find("terminate called"), std::string::npos) << output;
    ros::NodeHandle().deleteParam("/controlled_sim");
  }
  const std::string summary = "/tmp/birkhoff_cart_node_mains_" + std::to_string(::getpid()) + "_summary.txt";
  std::string output;
  const int status = run_node("cart_sim",
                              "__name:=controlled_sim _scene:=" + scene +
                                  " _integrator:=birkhoff_gauss6 _step_control:=adaptive _position_tolerance:=1e-6"
                                  " _duration:=2 _fast:=true _summary_path:=" + summary,
                              &output);
  EXPECT_EQ(status, 0) << output;
  EXPECT_NE(output.find("adaptive step control for 1e-06 m"), std::string::npos) << output;
  std::string text;
  run_command("cat " + summary, &text);
  EXPECT_NE(text.find("adaptive step control: position tolerance 1e-06 m"), std::string::npos) << text;
  EXPECT_NE(text.find("final t = 2 s"), std::string::npos) << text;
  std::remove(summary.c_str());
  ros::NodeHandle().deleteParam("/controlled_sim");
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "node_mains");
  ros::NodeHandle node;
  return RUN_ALL_TESTS();
}
