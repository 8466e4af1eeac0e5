// MissingJointCheck (missing_joint_check.h).
#include "birkhoff_cart/core/node_logic/missing_joint_check.h"

#include <algorithm>
#include <utility>

#include "birkhoff_cart/core/support/closest_name.h"

namespace birkhoff_cart {

MissingJointCheck::MissingJointCheck(std::string joint, double grace) : joint_(std::move(joint)), grace_(grace) {}

std::optional<std::size_t> MissingJointCheck::find(const std::vector<std::string>& names) {
  const auto found = std::find(names.begin(), names.end(), joint_);
  if (found == names.end()) return std::nullopt;
  if (!seen_) seen_ = true;
  return static_cast<std::size_t>(found - names.begin());
}

void MissingJointCheck::note_missing(const std::vector<std::string>& names, double now) {
  if (seen_) return;
  const std::lock_guard<std::mutex> lock(mutex_);
  if (!first_without_) {
    first_without_ = now;
    names_without_ = names;
  }
}

std::optional<std::string> MissingJointCheck::refusal(double now, const std::string& parameter,
                                                      const std::string& topic) const {
  if (seen_) return std::nullopt;
  std::vector<std::string> seen_names;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (!first_without_ || now - *first_without_ < grace_) return std::nullopt;
    seen_names = names_without_;
  }
  std::string names;
  for (const std::string& name : seen_names) names += (names.empty() ? "" : ", ") + name;
  const std::string guess = closest_name(joint_, seen_names);
  return "joint '" + joint_ + "' (" + parameter + ") is not in " + topic + ", which names " +
         (names.empty() ? "no joint" : names) + (guess.empty() ? "" : " (did you mean '" + guess + "'?)") +
         ": without the steering angle the controller cannot steer, so it does not run";
}

}  // namespace birkhoff_cart
