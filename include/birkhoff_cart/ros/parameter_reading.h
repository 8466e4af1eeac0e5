// Reading numbers from the parameter server the way users write them: every node of the package
// uses this one reader.
#pragma once

#include <string>

#include <ros/node_handle.h>

namespace birkhoff_cart {

/// The double parameter `name` of `node`, or `fallback` when it is not set. Accepts a double, an
/// integer (publish_rate: 100) or a string that is a whole number (roslaunch <param value="1e-3"/>
/// without a type). Throws std::invalid_argument naming the resolved parameter otherwise.
double read_double_parameter(const ros::NodeHandle& node, const std::string& name, double fallback);

}  // namespace birkhoff_cart
