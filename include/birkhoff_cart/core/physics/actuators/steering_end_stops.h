// Mechanical end stops of the steering hinge: |χ| ≤ χ_s as a documented event, not a penalty spring
// (docs/actuators.md §3, eqs. (S1)–(S4)). The simulation ends a step where χ reaches a stop
// (simulation.cpp locates the instant), applies the impact there (S1: p1 kept, ω2 → −e ω2), and while
// the axle rests on the stop adds the stop's reaction torque (S2) that holds χ̇ = 0 exactly; the axle
// leaves the stop where that reaction would have to pull (S3). Nothing here runs when a scene has no
// end stops.
#pragma once

#include <string>

#include "birkhoff_cart/core/physics/cart_model.h"
#include "birkhoff_cart/core/physics/effects.h"
#include "birkhoff_cart/core/physics/state.h"

namespace birkhoff_cart {

struct SteeringEndStopSettings {
  double angle = 0.0;        ///< χ_s: the stops sit at ±χ_s [rad], 0 < χ_s < π/2
  double restitution = 0.0;  ///< e: ω2 after an impact = −e ω2 before [-], 0 ≤ e ≤ 1
};

/// Throws std::invalid_argument naming `section`.key for a value out of range.
void validate_steering_end_stops(const std::string& section, const SteeringEndStopSettings& settings);

class SteeringEndStops {
 public:
  /// Which stop the axle rests on: none, +χ_s (upper) or −χ_s (lower).
  enum class Contact { kNone, kUpper, kLower };

  SteeringEndStops(const SteeringEndStopSettings& settings, const CartModel& model);
  const SteeringEndStopSettings& settings() const { return settings_; }

  Contact contact() const { return contact_; }
  void set_contact(Contact contact) { contact_ = contact; }

  /// How far χ lies beyond the nearer stop [rad]: > 0 past it, ≤ 0 inside.
  double penetration(double steering_angle) const { return std::abs(steering_angle) - settings_.angle; }

  /// While in contact: replaces Q2 of `total` by the value that holds ω̇2 = 0 (S2),
  ///   Q2 ← ν sin χ (Q1 − h1) / (μ + μ1 sin²χ) + h2,   h = (μ1 s c ω1 ω2, ν c ω1 ω2),
  /// with its Jacobian. Nothing when not in contact.
  void add_reaction(const EffectInput& input, GeneralizedForce& total) const;

  /// The stop's reaction torque λ = Q2(S2) − Q2 of the loads alone [N·m] at a state in contact:
  /// ≤ 0 on the upper stop and ≥ 0 on the lower one while the stop pushes (S3).
  double reaction(const EffectInput& input, const GeneralizedForce& loads) const;

  /// Would the stop `side` have to pull to hold the axle (λ of the wrong sign)? (S3)
  bool pulls(Contact side, double reaction_torque) const {
    return side == Contact::kUpper ? reaction_torque > 0.0 : reaction_torque < 0.0;
  }

  /// The impact at a stop (S1): χ set onto the stop, ω2 → −e ω2 with p1 = M11 ω1 + M12 ω2 kept; the
  /// energy change goes to applied_work and the impulse Δp2 to steering_impulse so that the
  /// balances (docs/derivation.md eqs. (3.7), (3.8)) still close. Returns the stop hit. `restitution`
  /// overrides e (0 for an impact that ends a bouncing sequence, §3.2).
  Contact impact(CartState& state) const { return impact(state, settings_.restitution); }
  Contact impact(CartState& state, double restitution) const;

  /// While held on stop `side` (S2: ω̇2 = 0 from ω2 = 0): χ set onto the stop exactly, where a
  /// step's round-off carried it past (by ~1e-15 rad; the energy it moves is below round-off).
  void hold_on_stop(CartState& state, Contact side) const;

 private:
  SteeringEndStopSettings settings_;
  const CartModel* model_;
  Contact contact_ = Contact::kNone;
};

}  // namespace birkhoff_cart
