// Small helpers shared by the rostest nodes: waiting on a condition while spinning (wall-clock
// timeouts only guard against hangs; the conditions are messages and sim time).
#pragma once

#include <functional>

#include <ros/ros.h>
#include <std_srvs/SetBool.h>

namespace birkhoff_cart_test {

/// Spins until `condition` holds or `timeout` [s of wall time] passes. Returns the condition.
inline bool wait_for(const std::function<bool()>& condition, double timeout) {
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(timeout);
  while (ros::ok() && ros::WallTime::now() < deadline) {
    ros::spinOnce();
    if (condition()) return true;
    ros::WallDuration(0.002).sleep();
  }
  ros::spinOnce();
  return condition();
}

/// Calls cart_sim's ~pause service. Returns false when the service is missing or fails.
inline bool set_paused(const std::string& service, bool paused) {
  if (!ros::service::waitForService(service, ros::Duration(20.0))) return false;
  std_srvs::SetBool call;
  call.request.data = paused;
  return ros::service::call(service, call) && call.response.success;
}

}  // namespace birkhoff_cart_test
