// cart_sim: the simulator node (docs/ros_interface.md, "ROS interface"). All the work is in CartSimNode.
// Exit codes: 0 finished or interrupted, 1 step failure, 2 refused at start, 3 record failure,
// 4 unexpected error (bag closed), 130 a second SIGINT/SIGTERM (bag left as <path>.active).

#include <cstdio>
#include <string>
#include <vector>

#include <ros/ros.h>
#include <rosgraph_msgs/Clock.h>

#include "birkhoff_cart/core/support/version.h"
#include "birkhoff_cart/ros/cart_sim_node.h"
#include "birkhoff_cart/ros/node_main.h"
#include "birkhoff_cart/ros/shutdown_signals.h"

namespace {

int run_node(ros::NodeHandle& node_handle) {
  try {
    birkhoff_cart::CartSimNode node(node_handle, ros::NodeHandle("~"));
    // The time loop polls the signal flag: a signal from here on leaves roscpp up for its clean end.
    const birkhoff_cart::SignalsPolled polled;
    return node.run();
  } catch (const birkhoff_cart::NodeStartupError& error) {
    if (birkhoff_cart::shutdown_signal_received()) {
      // roscpp was shut down by the signal while the node started (its log output with it).
      std::fprintf(stderr, "cart_sim: stopped by a shutdown signal while starting\n");
      return birkhoff_cart::CartSimNode::kExitFinished;
    }
    ROS_FATAL("cart_sim: %s", error.what());
    return birkhoff_cart::CartSimNode::kExitStartupFailure;
  } catch (const std::exception& error) {  // run() catches its own; this is construction or teardown
    ROS_FATAL("cart_sim: unexpected error: %s", error.what());
    return birkhoff_cart::CartSimNode::kExitInternalError;
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (birkhoff_cart::print_version_if_asked(argc, argv, "cart_sim")) return 0;
  // ros::init refuses a bad name or remapping by throwing: exit 2 with its message (node_main.h).
  return birkhoff_cart::run_node_main("cart_sim", [&] {
    // Log lines reach a file (roslaunch output="log", a redirect) as they happen, not at exit.
    std::setvbuf(stdout, nullptr, _IOLBF, 0);
    // roscpp subscribes every process to /clock under sim time; the clock source would hear back
    // each /clock it publishes (a thread wake-up each, ~1 µs per step in fast mode). Remap that
    // internal subscription away; CartSimNode publishes on the real /clock and sets its own time.
    std::vector<char*> arguments(argv, argv + argc);
    std::string unheard_clock = std::string("/clock:=") + birkhoff_cart::kUnheardClockTopic;
    arguments.push_back(unheard_clock.data());
    int argument_count = static_cast<int>(arguments.size());
    ros::init(argument_count, arguments.data(), "cart_sim", ros::init_options::NoSigintHandler);
    birkhoff_cart::install_shutdown_signal_handlers();
    // Outlives the node: when the last NodeHandle dies roscpp shuts down and drops later log output,
    // so the FATAL message below would be lost.
    ros::NodeHandle node_handle;
    // A publisher on the unheard topic that never publishes: the master's graph then shows roscpp's
    // moved subscription as connected, and roswtf's online checks stay clean.
    ros::Publisher unheard_clock_holder;
    if (ros::Time::isSimTime()) {
      unheard_clock_holder = node_handle.advertise<rosgraph_msgs::Clock>(birkhoff_cart::kUnheardClockTopic, 1);
    }
    const int exit_code = run_node(node_handle);
    if (exit_code == birkhoff_cart::CartSimNode::kExitFinished && !birkhoff_cart::shutdown_signal_received()) {
      bool end_launch = false;
      ros::param::get("~end_launch", end_launch);
      if (end_launch) birkhoff_cart::end_parent_launch(true);
    }
    return exit_code;
  });
}
