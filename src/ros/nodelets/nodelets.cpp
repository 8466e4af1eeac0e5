// The nodelets of birkhoff_cart (nodelet_plugins.xml, docs/ros_interface.md "Nodelets"): cart_sim,
// cmd_vel_controller and steering_pd_controller, loadable into one nodelet manager so that a closed
// loop exchanges its messages as shared pointers, without serialization. Each wraps the class its
// node executable runs; the executables stay.
#include <memory>
#include <stdexcept>
#include <thread>

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <ros/ros.h>

#include "birkhoff_cart/ros/cart_sim_node.h"
#include "birkhoff_cart/ros/cmd_vel_controller_node.h"
#include "birkhoff_cart/ros/shutdown_signals.h"
#include "birkhoff_cart/ros/steering_pd_controller.h"

namespace birkhoff_cart {

/// cart_sim as a nodelet: CartSimNode's time loop runs on a thread of its own (it owns its pace and
/// its callback queue, as in the node); unloading the nodelet ends the run as a shutdown signal would
/// (summary written, bag closed).
class CartSimNodelet : public nodelet::Nodelet {
 public:
  ~CartSimNodelet() override {
    if (node_) node_->request_stop();
    if (loop_.joinable()) loop_.join();
  }

 private:
  void onInit() override {
    try {
      node_ = std::make_unique<CartSimNode>(getNodeHandle(), getPrivateNodeHandle());
    } catch (const std::exception& error) {
      NODELET_FATAL("cart_sim: %s", error.what());
      return;
    }
    const bool end_launch = getPrivateNodeHandle().param("end_launch", false);
    loop_ = std::thread([this, end_launch] {
      const int exit_code = node_->run();
      NODELET_INFO("cart_sim: run ended (exit code %d as a node)", exit_code);
      // ~end_launch: the launch ends with the run, as with the node (its manager is stopped by roslaunch).
      if (end_launch && exit_code == CartSimNode::kExitFinished) end_parent_launch(false);
    });
  }

  std::unique_ptr<CartSimNode> node_;
  std::thread loop_;
};

/// cmd_vel_controller as a nodelet; a refusal (a wrong ~steering_joint) stops this nodelet only.
class CmdVelControllerNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    try {
      node_ = std::make_unique<CmdVelControllerNode>(getNodeHandle(), getPrivateNodeHandle(), false);
    } catch (const std::invalid_argument& error) {
      NODELET_FATAL("cmd_vel_controller: bad parameter: %s", error.what());
    }
  }
  std::unique_ptr<CmdVelControllerNode> node_;
};

/// steering_pd_controller as a nodelet. With ~inline_answers (default true) it answers each
/// joint_states inside the publisher's publish(): in cart_sim's manager the lockstep barrier then
/// finds both torques queued and no thread is woken.
class SteeringPdControllerNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    try {
      const bool inline_answers = getPrivateNodeHandle().param("inline_answers", true);
      controller_ = std::make_unique<SteeringPdController>(getNodeHandle(), getPrivateNodeHandle(), inline_answers,
                                                          /*shut_down_on_refusal=*/false);
    } catch (const std::invalid_argument& error) {
      NODELET_FATAL("steering_pd_controller: %s", error.what());
    }
  }
  std::unique_ptr<SteeringPdController> controller_;
};

}  // namespace birkhoff_cart

PLUGINLIB_EXPORT_CLASS(birkhoff_cart::CartSimNodelet, nodelet::Nodelet)
PLUGINLIB_EXPORT_CLASS(birkhoff_cart::CmdVelControllerNodelet, nodelet::Nodelet)
PLUGINLIB_EXPORT_CLASS(birkhoff_cart::SteeringPdControllerNodelet, nodelet::Nodelet)
