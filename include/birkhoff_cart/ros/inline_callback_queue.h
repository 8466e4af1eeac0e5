// A callback "queue" that runs each callback at once, in the thread that queues it. A subscription
// on it is served inside the publisher's publish() when both are in one process (nodelets): the
// steering_pd_controller nodelet answers cart_sim's joint_states before cart_sim's publish returns,
// so a lockstep barrier finds the answers queued and no thread is woken (docs/ros_interface.md,
// "Nodelets"). Only for callbacks that are quick and never publish on the topic that called them.
#pragma once

#include <ros/callback_queue_interface.h>

namespace birkhoff_cart {

class InlineCallbackQueue : public ros::CallbackQueueInterface {
 public:
  void addCallback(const ros::CallbackInterfacePtr& callback, uint64_t /*owner_id*/ = 0) override {
    // A subscription callback answers TryAgain only while another thread runs it; inline, none does.
    while (callback->call() == ros::CallbackInterface::TryAgain) {
    }
  }
  void removeByID(uint64_t /*owner_id*/) override {}
};

}  // namespace birkhoff_cart
