// Where a torque effect takes its torque from: a time profile or a shared command input.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>

#include "birkhoff_cart/core/integrators/deterministic_math.h"
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

  /// The torque at time t [N·m]. A smooth profile's value (a cos or a tanh) is remembered for the
  /// last times asked: a collocation step evaluates the loads at the same s stage times in every
  /// iteration of its stage solve, so it costs one cos or tanh per stage time instead of one per
  /// evaluation (on drive_rr_drag the two profiles were 11 % of a controlled run's instructions).
  /// The memo is the object's own, so a TorqueSource serves one thread at a time (as the
  /// Simulation that owns it does).
  double at(double time) const {
    if (actuator_) return actuator_->output_at(time);
    if (command_) return command_->value;
    if (profile_.kind != TorqueProfile::Kind::kCosine && profile_.kind != TorqueProfile::Kind::kSmoothSwitchOff) {
      return profile_.at(time);
    }
    const std::uint64_t bits = deterministic::bits_of(time);
    MemoEntry& entry = memo_[(bits * 0x9E3779B97F4A7C15ULL) >> (64 - kMemoBits)];  // Fibonacci hashing
    if (entry.time_bits != bits) {
      entry.value = profile_.at(time);
      entry.time_bits = bits;
    }
    return entry.value;
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
  /// An empty entry holds a NaN time with a NaN value: what the profile gives at that time too.
  struct MemoEntry {
    std::uint64_t time_bits = 0x7FF8000000000000ULL;              ///< the time asked, bit for bit
    double value = std::numeric_limits<double>::quiet_NaN();  ///< profile_.at(time) [N·m]
  };
  static constexpr int kMemoBits = 3;  ///< 8 entries: the 4-stage member's stage times and its step's ends

  TorqueProfile profile_;
  std::shared_ptr<CommandInput> command_;
  std::shared_ptr<TorqueActuator> actuator_;
  mutable std::array<MemoEntry, 1 << kMemoBits> memo_{};
};

/// Throws std::invalid_argument naming `effect_name` and the profile field that is unusable
/// (non-finite value, negative frequency, width ≤ 0, ramp end before start).
void validate_torque_profile(const std::string& effect_name, const TorqueProfile& profile);

}  // namespace birkhoff_cart
