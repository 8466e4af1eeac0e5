// Reading numbers from the parameter server the way users write them: every node of the package
// uses this one reader.
#pragma once

#include <string>
#include <vector>

#include <ros/node_handle.h>

namespace birkhoff_cart {

/// The double parameter `name` of `node`, or `fallback` when it is not set. Accepts a double, an
/// integer (publish_rate: 100) or a string that is a whole number (roslaunch <param value="1e-3"/>
/// without a type). Throws std::invalid_argument naming the resolved parameter otherwise.
double read_double_parameter(const ros::NodeHandle& node, const std::string& name, double fallback);

/// What the parameter server holds at `name` of `node`, for a refusal that names it: "the int 1",
/// "the string 'yes'", "the double 0.5", "the bool true", "a list of 3 values", "a dictionary".
std::string describe_parameter_value(const ros::NodeHandle& node, const std::string& name);

/// One line for each parameter on the master under `private_node`'s namespace that the node does
/// not read (a typo is otherwise ignored without a word): its name, and the closest of `known`
/// (names relative to the namespace, "linear/x/max_velocity") when one is within a typo's reach.
/// A known name ending in '/' covers everything below it.
std::vector<std::string> unknown_private_parameters(const ros::NodeHandle& private_node,
                                                    const std::vector<std::string>& known);

}  // namespace birkhoff_cart
