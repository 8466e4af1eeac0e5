// The package's one reader of numeric parameters (see parameter_reading.h).
#include "birkhoff_cart/ros/parameter_reading.h"

#include <sstream>
#include <stdexcept>

#include <ros/param.h>

#include "birkhoff_cart/core/support/closest_name.h"

#include <XmlRpcValue.h>

namespace birkhoff_cart {

double read_double_parameter(const ros::NodeHandle& node, const std::string& name, double fallback) {
  XmlRpc::XmlRpcValue value;
  if (!node.getParam(name, value)) return fallback;
  if (value.getType() == XmlRpc::XmlRpcValue::TypeDouble) return static_cast<double>(value);
  if (value.getType() == XmlRpc::XmlRpcValue::TypeInt) return static_cast<int>(value);
  if (value.getType() == XmlRpc::XmlRpcValue::TypeString) {
    const std::string text = static_cast<std::string>(value);
    try {
      std::size_t used = 0;
      const double parsed = std::stod(text, &used);
      if (used == text.size()) return parsed;
    } catch (const std::exception&) {
    }
  }
  throw std::invalid_argument("parameter " + node.resolveName(name) + " must be a number, got " +
                              describe_parameter_value(node, name));
}

std::string describe_parameter_value(const ros::NodeHandle& node, const std::string& name) {
  XmlRpc::XmlRpcValue value;
  if (!node.getParam(name, value)) return "nothing";
  switch (value.getType()) {
    case XmlRpc::XmlRpcValue::TypeBoolean: return std::string("the bool ") + (static_cast<bool>(value) ? "true" : "false");
    case XmlRpc::XmlRpcValue::TypeInt: return "the int " + std::to_string(static_cast<int>(value));
    case XmlRpc::XmlRpcValue::TypeDouble: {
      std::ostringstream text;
      text << "the double " << static_cast<double>(value);
      return text.str();
    }
    case XmlRpc::XmlRpcValue::TypeString: return "the string '" + static_cast<std::string>(value) + "'";
    case XmlRpc::XmlRpcValue::TypeArray: return "a list of " + std::to_string(value.size()) + " values";
    case XmlRpc::XmlRpcValue::TypeStruct: return "a dictionary";
    default: return "a value of another type";
  }
}

std::vector<std::string> unknown_private_parameters(const ros::NodeHandle& private_node,
                                                    const std::vector<std::string>& known) {
  std::vector<std::string> all;
  std::vector<std::string> reports;
  if (!ros::param::getParamNames(all)) return reports;  // no master answer: nothing to say
  const std::string prefix = private_node.getNamespace() + "/";
  for (const std::string& name : all) {
    if (name.compare(0, prefix.size(), prefix) != 0) continue;
    const std::string relative = name.substr(prefix.size());
    bool read = false;
    for (const std::string& entry : known) {
      read = read || relative == entry ||
             (!entry.empty() && entry.back() == '/' && relative.compare(0, entry.size(), entry) == 0);
    }
    if (read) continue;
    const std::string guess = closest_name(relative, known);
    reports.push_back("parameter " + name + " is not one of this node's and is ignored" +
                      (guess.empty() ? std::string(" (docs/ros_interface.md lists them)")
                                     : " (did you mean " + prefix + guess + "?)"));
  }
  return reports;
}

}  // namespace birkhoff_cart
