// What the step controls' adapters (adaptive_cart_stepper.h, reversible_cart_stepper.h,
// dopri5_cart_stepper.h) share about the caller's output instants: which must be exact (landings: the
// run's end, land_on() instants; every output of a scene whose effects take commands, since a new
// command may start there) and whether the commands changed since the last output (the grid then
// restarts there). Private to the core library.
#pragma once

#include <cmath>
#include <limits>
#include <set>

#include "birkhoff_cart/core/physics/effects.h"

namespace birkhoff_cart {

class OutputInstants {
 public:
  explicit OutputInstants(const EffectSet& effects) : effects_(&effects) {}

  void land_on(double time) { landings_.insert(time); }

  /// The output instant t + h [s], snapped onto a landing within round-off of it (a caller's
  /// t₀ + n·h and the landing t₀ + T may differ by an ulp).
  double target(double time, double step_size) const {
    const double target = time + step_size;
    const double close = 16.0 * std::numeric_limits<double>::epsilon() * std::max(1.0, std::abs(target));
    const auto near = landings_.lower_bound(target - close);
    return near != landings_.end() && *near <= target + close ? *near : target;
  }
  /// Must the state at `target` be exact (a landing, or any output of a commanded scene)?
  bool exact_at(double target) const { return commanded() || landings_.count(target) > 0; }
  /// The first landing after t [s] (+inf: none).
  double next_landing_after(double t) const {
    const auto next = landings_.upper_bound(t);
    return next == landings_.end() ? std::numeric_limits<double>::infinity() : *next;
  }

  /// Do the scene's effects take commands?
  bool commanded() const { return effects_->steering_command() || effects_->drive_command(); }
  /// Have the commands changed since remember_commands()?
  bool commands_changed() const {
    const auto& steering = effects_->steering_command();
    const auto& drive = effects_->drive_command();
    return (steering && steering->value != steering_command_) || (drive && drive->value != drive_command_);
  }
  void remember_commands() {
    if (effects_->steering_command()) steering_command_ = effects_->steering_command()->value;
    if (effects_->drive_command()) drive_command_ = effects_->drive_command()->value;
  }

 private:
  const EffectSet* effects_;
  std::set<double> landings_;      ///< [s]
  double steering_command_ = 0.0;  ///< the commands the grid was started or continued with [N·m]
  double drive_command_ = 0.0;
};

}  // namespace birkhoff_cart
