// Steering torque τ(t) between rear body and front axle: Q = (0, τ)   (docs/derivation.md eq. (4.1)).
#pragma once

#include <string>

#include "birkhoff_cart/core/physics/effects.h"
#include "birkhoff_cart/core/physics/effects/torque_source.h"

namespace birkhoff_cart {

class SteeringTorque : public Effect {
 public:
  explicit SteeringTorque(TorqueSource source) : source_(std::move(source)) {}
  const std::string& name() const override;
  /// Q += (0, τ(t)); ∂Q/∂(χ, ω1, ω2) = 0.
  void add_to(const EffectInput& input, GeneralizedForce& total) const override;
  const TorqueSource& source() const { return source_; }
  bool depends_on_time() const override { return source_.depends_on_time(); }
  double next_kink_after(double t) const override { return source_.next_kink_after(t); }

 private:
  TorqueSource source_;
};

}  // namespace birkhoff_cart
