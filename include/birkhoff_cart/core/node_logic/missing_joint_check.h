// Whether a controller's joint is in joint_states (cmd_vel_controller, steering_pd_controller): a
// message without it may be another publisher's partial joint_states, so the name is refused only
// when none has held it for `grace` of wall time after the first that did not. The refusal names
// the joints seen and the closest of them. Thread-safe: observe() may run on a publisher's thread
// (a nodelet answering inline) while refusal() runs on a timer. ROS-free (missing_joint_check_test).
#pragma once

#include <atomic>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace birkhoff_cart {

class MissingJointCheck {
 public:
  /// `joint`: the name looked for; `grace` [s of wall time] ≥ 0.
  explicit MissingJointCheck(std::string joint, double grace = 1.0);

  /// A joint_states message's `names`: its index of the joint, or none (then call note_missing).
  std::optional<std::size_t> find(const std::vector<std::string>& names);
  /// A message whose `names` lack the joint, at wall time `now` [s] (only the first one counts).
  void note_missing(const std::vector<std::string>& names, double now);
  /// Some message has held the joint: the check is over.
  bool seen() const { return seen_; }
  /// At wall time `now` [s]: the refusal, once `grace` has passed since the first message without
  /// the joint and none held it — "joint 'J' (`parameter`) is not in `topic`, which names A, B
  /// (did you mean 'A'?): without the steering angle the controller cannot steer, so it does not run".
  std::optional<std::string> refusal(double now, const std::string& parameter, const std::string& topic) const;

  const std::string& joint() const { return joint_; }

 private:
  std::string joint_;
  double grace_;  ///< [s]
  std::atomic<bool> seen_{false};
  mutable std::mutex mutex_;
  std::optional<double> first_without_;  ///< wall time of the first message without the joint [s]
  std::vector<std::string> names_without_;  ///< the joints that message named
};

}  // namespace birkhoff_cart
