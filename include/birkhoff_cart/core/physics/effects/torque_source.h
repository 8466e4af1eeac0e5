// Where a torque effect takes its torque from: a time profile or a shared command input.
#pragma once

#include <limits>
#include <memory>
#include <string>

#include "birkhoff_cart/core/physics/actuators/torque_actuator.h"
#include "birkhoff_cart/core/physics/effects.h"
#include "birkhoff_cart/core/physics/torque_profile.h"

namespace birkhoff_cart {

class TorqueSource {
 public:
  /// With a non-null `command` the torque is command->value (zero-order hold); else profile.at(t).
  /// With an `actuator` (docs/actuators.md) the torque is the actuator's response to the command or
  /// piecewise-constant profile, which the simulation feeds to it.
  explicit TorqueSource(const TorqueProfile& profile, std::shared_ptr<CommandInput> command = nullptr,
                        std::shared_ptr<TorqueActuator> actuator = nullptr)
      : profile_(profile), command_(std::move(command)), actuator_(std::move(actuator)) {}

  /// The torque at time t [N·m].
  double at(double time) const {
    if (actuator_) return actuator_->output_at(time);
    return command_ ? command_->value : profile_.at(time);
  }

  /// A profile that varies in time (a command is held constant between commands), or an actuator.
  bool depends_on_time() const {
    return actuator_ || (!command_ && profile_.kind != TorqueProfile::Kind::kConstant);
  }
  /// The first time > t [s] where the torque has a kink or jump (none for a command without an
  /// actuator: its changes are seen by the integrators as command changes).
  double next_kink_after(double t) const {
    if (actuator_) return actuator_->next_kink_after(t);
    return command_ ? std::numeric_limits<double>::infinity() : profile_.next_kink_after(t);
  }
  const TorqueProfile& profile() const { return profile_; }
  const std::shared_ptr<CommandInput>& command() const { return command_; }

 private:
  TorqueProfile profile_;
  std::shared_ptr<CommandInput> command_;
  std::shared_ptr<TorqueActuator> actuator_;
};

/// Throws std::invalid_argument naming `effect_name` and the profile field that is unusable
/// (non-finite value, negative frequency, width ≤ 0, ramp end before start).
void validate_torque_profile(const std::string& effect_name, const TorqueProfile& profile);

}  // namespace birkhoff_cart
