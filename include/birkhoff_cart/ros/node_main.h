// The last net of every node's main(): no exception leaves main (std::terminate would end the
// process with exit 134, no message of its own and, for cart_sim, the record unfinished).
// roscpp throws from ros::init, NodeHandle, advertise and subscribe for a name it refuses
// (`__name:=9x`, `__ns:=/a!b`, a remapping `odom:=a!b`): that is a refusal at start, exit 2, with
// one line naming the node and the name. Anything else that escapes is an internal error, exit 4.
#pragma once

#include <functional>

namespace birkhoff_cart {

/// Exit status of a node refused at start (bad parameter, name or remapping) [-].
constexpr int kNodeExitRefused = 2;
/// Exit status of a node stopped by an unexpected exception [-].
constexpr int kNodeExitInternalError = 4;

/// Runs `body` (the node's main after --version) and returns its exit status; an exception that
/// escapes it is printed as "<node>: ..." (ROS_FATAL once roscpp is initialized, stderr before)
/// and mapped to kNodeExitRefused (ros::InvalidNameException) or kNodeExitInternalError.
int run_node_main(const char* node, const std::function<int()>& body);

}  // namespace birkhoff_cart
