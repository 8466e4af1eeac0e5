// Torque time profiles of the steering and drive torques (docs/scenes.md "Torque profiles").
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "birkhoff_cart/core/physics/effects/torque_source.h"
#include "birkhoff_cart/core/integrators/deterministic_math.h"
#include "birkhoff_cart/core/physics/torque_profile.h"

namespace birkhoff_cart {

double TorqueProfile::at(double time) const {
  switch (kind) {
    case Kind::kConstant:
    case Kind::kCommand:
      return value;
    case Kind::kCosine:
      // τ(t) = A cos(2π f t + φ)
      return amplitude * deterministic::cos(2.0 * M_PI * frequency * time + phase);
    case Kind::kStep:
      return time < step_time ? initial : final;
    case Kind::kRamp: {
      if (time <= start_time) return initial;
      if (time >= end_time) return final;
      const double fraction = (time - start_time) / (end_time - start_time);  // [-]
      return initial + fraction * (final - initial);
    }
    case Kind::kSmoothSwitchOff:
      // τ(t) = τ0 · ½ (1 − tanh((t − t_off)/w))
      return initial * 0.5 * (1.0 - deterministic::tanh((time - switch_off_time) / width));
  }
  return 0.0;
}

double TorqueProfile::next_kink_after(double t) const {
  double kink = std::numeric_limits<double>::infinity();
  const auto consider = [&](double time) {
    if (time > t && time < kink) kink = time;
  };
  if (kind == Kind::kStep) consider(step_time);
  if (kind == Kind::kRamp) {
    consider(start_time);
    consider(end_time);
  }
  return kink;
}

void validate_torque_profile(const std::string& effect_name, const TorqueProfile& profile) {
  auto fail = [&](const char* field, const std::string& problem) {
    std::ostringstream message;
    message << "effect '" << effect_name << "': profile field '" << field << "' " << problem;
    throw std::invalid_argument(message.str());
  };
  const std::pair<const char*, double> fields[] = {
      {"value", profile.value},         {"amplitude", profile.amplitude},
      {"frequency", profile.frequency}, {"phase", profile.phase},
      {"initial", profile.initial},     {"final", profile.final},
      {"step_time", profile.step_time}, {"start_time", profile.start_time},
      {"end_time", profile.end_time},   {"switch_off_time", profile.switch_off_time},
      {"width", profile.width},
  };
  for (const auto& [field, value] : fields) {
    if (!std::isfinite(value)) fail(field, "must be finite");
  }
  if (profile.frequency < 0.0) fail("frequency", "must be >= 0 Hz");
  if (profile.kind == TorqueProfile::Kind::kSmoothSwitchOff && !(profile.width > 0.0)) {
    fail("width", "must be > 0 s");
  }
  if (profile.kind == TorqueProfile::Kind::kRamp && !(profile.end_time > profile.start_time)) {
    fail("end_time", "must be later than start_time");
  }
}

}  // namespace birkhoff_cart
