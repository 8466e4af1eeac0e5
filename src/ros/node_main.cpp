// run_node_main (node_main.h): the last net of every node's main().
#include "birkhoff_cart/ros/node_main.h"

#include <cstdio>
#include <exception>
#include <string>

#include <ros/exceptions.h>
#include <ros/names.h>
#include <ros/ros.h>

namespace birkhoff_cart {
namespace {

void report(const char* node, const std::string& what) {
  // Before ros::init succeeded rosconsole may not be set up: plain stderr then.
  if (ros::isInitialized()) {
    ROS_FATAL("%s: %s", node, what.c_str());
  } else {
    std::fprintf(stderr, "%s: %s\n", node, what.c_str());
  }
}

}  // namespace

int run_node_main(const char* node, const std::function<int()>& body) {
  try {
    return body();
  } catch (const ros::InvalidNameException& error) {
    report(node, std::string("refused at start: a node name, namespace or remapping is not a valid ROS name: ") +
                     error.what());
    return kNodeExitRefused;
  } catch (const std::exception& error) {
    report(node, std::string("unexpected error: ") + error.what());
  } catch (...) {
    report(node, "unexpected error of unknown type");
  }
  return kNodeExitInternalError;
}

}  // namespace birkhoff_cart
