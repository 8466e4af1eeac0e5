// Drive torque T(t), the total on the rear axle: Q = (T cos χ / r1, 0)   (docs/derivation.md eq. (4.2)).
#pragma once

#include <string>

#include "birkhoff_cart/core/physics/effects.h"
#include "birkhoff_cart/core/physics/effects/torque_source.h"

namespace birkhoff_cart {

class DriveTorque : public Effect {
 public:
  /// rear_wheel_radius r1 [m], > 0.
  DriveTorque(TorqueSource source, double rear_wheel_radius);
  const std::string& name() const override;
  /// Q1 += T cos χ / r1;  ∂Q1/∂χ += −T sin χ / r1.
  void add_to(const EffectInput& input, GeneralizedForce& total) const override;
  const TorqueSource& source() const { return source_; }
  bool depends_on_time() const override { return source_.depends_on_time(); }
  double next_kink_after(double t) const override { return source_.next_kink_after(t); }

 private:
  TorqueSource source_;
  double rear_wheel_radius_;  ///< r1 [m]
};

}  // namespace birkhoff_cart
