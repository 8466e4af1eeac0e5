// steering_driver: an example of driving cart_sim from another node. Publishes a steering-torque
// profile τ(t) = offset + amplitude · sin(2π frequency t) [N·m] on `steering_torque`
// (std_msgs/Float64) at ~rate Hz of ROS time (sim time when /use_sim_time is true, so it follows
// cart_sim's /clock). Use it with a scene whose steering_torque source is `command`
// (config/scenes/driven.yaml); launch/driven.launch starts both.
// Exit codes: 0 shut down, 2 refused at start (bad parameter, name or remapping), 4 unexpected error.
#include <cmath>
#include <string>

#include <ros/ros.h>
#include <std_msgs/Float64.h>
#include "birkhoff_cart/core/support/version.h"
#include "birkhoff_cart/ros/node_main.h"
#include "birkhoff_cart/ros/parameter_reading.h"

namespace {

constexpr double kLowestRate = 1e-6;  // [Hz]: a period of 1e6 s, inside ros::Duration's 2^31 s
constexpr double kHighestRate = 1e6;  // [Hz]: a period of 1 µs, well above ros::Duration's 1 ns

}  // namespace

int main(int argc, char** argv) {
  if (birkhoff_cart::print_version_if_asked(argc, argv, "steering_driver")) return 0;
  return birkhoff_cart::run_node_main("steering_driver", [&] {
    ros::init(argc, argv, "steering_driver");
    ros::NodeHandle node;
    ros::NodeHandle private_node("~");
    const double amplitude = private_node.param("amplitude", 2.0);  // [N·m]
    const double frequency = private_node.param("frequency", 0.2);  // [Hz]
    const double offset = private_node.param("offset", 0.0);        // [N·m]
    const double rate = private_node.param("rate", 50.0);           // [Hz]
    for (const std::string& report :
         birkhoff_cart::unknown_private_parameters(private_node, {"amplitude", "frequency", "offset", "rate"})) {
      ROS_WARN("steering_driver: %s", report.c_str());
    }
    // The timer period 1/rate must be a ros::Duration (at most 2^31 - 1 s) and longer than 0 ns.
    if (!(rate >= kLowestRate && rate <= kHighestRate) || !std::isfinite(amplitude) || !std::isfinite(frequency) ||
        !std::isfinite(offset)) {
      ROS_FATAL("steering_driver: ~rate must be in [%g, %g] Hz (got %g) and ~amplitude, ~frequency, ~offset finite",
                kLowestRate, kHighestRate, rate);
      return birkhoff_cart::kNodeExitRefused;
    }
    ros::Publisher publisher = node.advertise<std_msgs::Float64>("steering_torque", 10);
    // With sim time the timer waits for the simulator's /clock; a tick at t publishes τ(t).
    ros::Timer timer = node.createTimer(ros::Duration(1.0 / rate), [&](const ros::TimerEvent& event) {
      std_msgs::Float64 torque;
      const double time = event.current_real.toSec();  // [s]
      torque.data = offset + amplitude * std::sin(2.0 * M_PI * frequency * time);
      publisher.publish(torque);
    });
    ROS_INFO("steering_driver: tau(t) = %g + %g sin(2 pi %g t) N m at %g Hz on %s", offset, amplitude, frequency,
             rate, publisher.getTopic().c_str());
    ros::spin();
    return 0;
  });
}
