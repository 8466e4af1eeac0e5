// The members the adaptive step control refuses although they have a local error estimate: their
// estimate cannot steer the run to the tolerance asked (measured: docs/accuracy.md §4.4). The reason
// is the member's own, in integrator_members.h; the registry's row then has no adaptive factory
// (integrator_registry.cpp), and every face (make_cart_stepper, the scene reader, the CLI, the node,
// the Python module) says why with adaptive_refusal_message.
#pragma once

#include <string>

namespace birkhoff_cart {

/// Why step_control adaptive is refused to the member `name`; nullptr when it is not refused for
/// its estimate (a member without an estimate is not offered the control at all).
const char* adaptive_refusal(const std::string& name);

/// "step_control 'adaptive' is for (<the members that take it>), not '<name>'", followed by
/// ": <adaptive_refusal(name)>" where the member has a reason.
std::string adaptive_refusal_message(const std::string& name);

}  // namespace birkhoff_cart
