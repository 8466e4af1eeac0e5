// The package's one reader of numeric parameters (see parameter_reading.h).
#include "birkhoff_cart/ros/parameter_reading.h"

#include <stdexcept>

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
  throw std::invalid_argument("parameter " + node.resolveName(name) + " must be a number");
}

}  // namespace birkhoff_cart
