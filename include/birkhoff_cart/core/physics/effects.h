// Loads on the cart as composable effects. A scene enables effects by name; only enabled effects
// exist in the EffectSet, so a disabled effect is never evaluated and costs nothing.
// Generalized forces (Q1 [N], Q2 [N·m]) follow docs/derivation.md §4.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "birkhoff_cart/core/integrators/autodiff.h"
#include "birkhoff_cart/core/integrators/deterministic_math.h"
#include "birkhoff_cart/core/physics/cart_model.h"

namespace birkhoff_cart {

class SteeringEndStops;
class TorqueActuator;

/// Where an effect reads the state: time and the reduced velocity state.
struct EffectInput {
  double time = 0.0;            ///< t [s]
  double steering_angle = 0.0;  ///< χ [rad]
  double forward_speed = 0.0;   ///< ω1 [m/s]
  double steering_rate = 0.0;   ///< ω2 [rad/s]
  /// sin χ and cos χ [-] where the caller already has them (the right-hand side computes them once
  /// per evaluation; for the stages, in one vector call): deterministic::sin and cos of χ bit for
  /// bit, so the loads are the same with or without them. NaN: not given, the effects compute them.
  double steering_sin = std::numeric_limits<double>::quiet_NaN();
  double steering_cos = std::numeric_limits<double>::quiet_NaN();

  double sin_steering_angle() const { return std::isnan(steering_sin) ? deterministic::sin(steering_angle) : steering_sin; }
  double cos_steering_angle() const { return std::isnan(steering_cos) ? deterministic::cos(steering_angle) : steering_cos; }
};

/// Generalized force and its analytic Jacobian (used by Newton's method and by AD).
struct GeneralizedForce {
  Eigen::Vector2d force = Eigen::Vector2d::Zero();                ///< (Q1 [N], Q2 [N·m])
  Eigen::Matrix<double, 2, 3> jacobian = Eigen::Matrix<double, 2, 3>::Zero();  ///< ∂Q/∂(χ, ω1, ω2)
};

/// A commanded value (a torque) written by the outside world (the ROS node) and read by an
/// effect whose source is `command`: zero-order hold until the next write.
struct CommandInput {
  double value = 0.0;  ///< [N·m]
};

/// One load. Implementations live in src/core/physics/effects/.
class Effect {
 public:
  virtual ~Effect() = default;
  /// The scene name of the effect (steering_torque, drive_torque, rolling_resistance, ...).
  virtual const std::string& name() const = 0;
  /// Adds this effect's Q and ∂Q/∂(χ, ω1, ω2) to `total`.
  virtual void add_to(const EffectInput& input, GeneralizedForce& total) const = 0;
  /// Is Q 2π-periodic in the steering angle χ? (Lets the integrators keep χ reduced; a hinge spring is not.)
  virtual bool periodic_in_steering_angle() const { return true; }
  /// Does Q change with time t at a fixed state (a torque profile)? (The reversible step control
  /// then adds ∂σ/∂t to its step density's rate.)
  virtual bool depends_on_time() const { return false; }
  /// The first time > t [s] where Q is not smooth in t (a torque step, a ramp's corners); +∞ if
  /// none. Integrators that choose their own steps land on it (reversible_cart_stepper.h).
  virtual double next_kink_after(double /*t*/) const { return std::numeric_limits<double>::infinity(); }
};

/// The enabled effects of a scene.
class EffectSet {
 public:
  void add(std::unique_ptr<Effect> effect);
  bool empty() const { return effects_.empty(); }
  /// Every enabled effect 2π-periodic in χ?
  bool periodic_in_steering_angle() const {
    for (const auto& effect : effects_) {
      if (!effect->periodic_in_steering_angle()) return false;
    }
    return true;
  }
  /// Any enabled effect that changes with t at a fixed state?
  bool depends_on_time() const {
    for (const auto& effect : effects_) {
      if (effect->depends_on_time()) return true;
    }
    return false;
  }
  /// The first time > t [s] where any enabled effect has a kink in time; +∞ if none.
  double next_kink_after(double t) const {
    double kink = std::numeric_limits<double>::infinity();
    for (const auto& effect : effects_) kink = std::min(kink, effect->next_kink_after(t));
    return kink;
  }
  std::size_t size() const { return effects_.size(); }
  const std::vector<std::unique_ptr<Effect>>& effects() const { return effects_; }

  /// Sum of all enabled effects (zero for the free cart), with the end stops' holding reaction
  /// while the steering axle rests on a stop (docs/actuators.md eq. (S2)).
  GeneralizedForce evaluate(const EffectInput& input) const;
  /// Sum of the effects alone, without the end stops' reaction.
  GeneralizedForce evaluate_loads(const EffectInput& input) const;

  /// Q with its Jacobian ∂Q/∂(χ, ω1, ω2) at a point (zero when no effect and no end stop acts): for
  /// analytic Jacobians of the rates (cart_birkhoffian.h darboux_jacobian).
  /// `steering_sin`, `steering_cos`: sin χ and cos χ where the caller has them (EffectInput), else NaN.
  GeneralizedForce force_and_jacobian(double time, double steering_angle, const Vector2<double>& quasi_velocity,
                                      double steering_sin = std::numeric_limits<double>::quiet_NaN(),
                                      double steering_cos = std::numeric_limits<double>::quiet_NaN()) const {
    if (effects_.empty() && !end_stops_) return GeneralizedForce{};
    EffectInput input;
    input.time = time;
    input.steering_angle = steering_angle;
    input.forward_speed = quasi_velocity(0);
    input.steering_rate = quasi_velocity(1);
    input.steering_sin = steering_sin;
    input.steering_cos = steering_cos;
    return evaluate(input);
  }

  /// Q as scalars of type S: plain values for double, values with derivatives propagated through
  /// the analytic Jacobian for AD scalars (t is never differentiated).
  /// `steering_sin`, `steering_cos`: as force_and_jacobian's.
  template <class S>
  Vector2<S> generalized_force(double time, const S& steering_angle, const Vector2<S>& quasi_velocity,
                               double steering_sin = std::numeric_limits<double>::quiet_NaN(),
                               double steering_cos = std::numeric_limits<double>::quiet_NaN()) const {
    if (effects_.empty() && !end_stops_) {  // small, so that every right-hand side inlines it
      Vector2<S> none;
      none.setConstant(S(0.0) * steering_angle);
      return none;
    }
    return generalized_force_of_loads(time, steering_angle, quasi_velocity, steering_sin, steering_cos);
  }

 private:
  /// generalized_force where an effect or the end stops are enabled.
  template <class S>
  Vector2<S> generalized_force_of_loads(double time, const S& steering_angle, const Vector2<S>& quasi_velocity,
                                        double steering_sin, double steering_cos) const {
    Vector2<S> result;
    const GeneralizedForce total =
        force_and_jacobian(time, value_of(steering_angle), Vector2<double>(value_of(quasi_velocity(0)), value_of(quasi_velocity(1))),
                           steering_sin, steering_cos);
    const S inputs[3] = {steering_angle, quasi_velocity(0), quasi_velocity(1)};
    for (int row = 0; row < 2; ++row) {
      const double partials[3] = {total.jacobian(row, 0), total.jacobian(row, 1), total.jacobian(row, 2)};
      result(row) = chain(total.force(row), partials, inputs, 3);
    }
    return result;
  }

 public:

  /// The command inputs of effects whose source is `command` (nullptr when none).
  std::shared_ptr<CommandInput> steering_command() const { return steering_command_; }
  std::shared_ptr<CommandInput> drive_command() const { return drive_command_; }
  void set_steering_command_input(std::shared_ptr<CommandInput> input) { steering_command_ = std::move(input); }
  void set_drive_command_input(std::shared_ptr<CommandInput> input) { drive_command_ = std::move(input); }

  /// The actuators between the commands (or piecewise-constant profiles) and the torque effects, and
  /// the steering end stops, when the scene enables them (nullptr otherwise; docs/actuators.md).
  std::shared_ptr<TorqueActuator> steering_actuator() const { return steering_actuator_; }
  std::shared_ptr<TorqueActuator> drive_actuator() const { return drive_actuator_; }
  std::shared_ptr<SteeringEndStops> end_stops() const { return end_stops_; }
  void set_steering_actuator(std::shared_ptr<TorqueActuator> actuator) { steering_actuator_ = std::move(actuator); }
  void set_drive_actuator(std::shared_ptr<TorqueActuator> actuator) { drive_actuator_ = std::move(actuator); }
  void set_end_stops(std::shared_ptr<SteeringEndStops> stops) { end_stops_ = std::move(stops); }

 private:
  std::vector<std::unique_ptr<Effect>> effects_;
  std::shared_ptr<CommandInput> steering_command_;
  std::shared_ptr<CommandInput> drive_command_;
  std::shared_ptr<TorqueActuator> steering_actuator_;
  std::shared_ptr<TorqueActuator> drive_actuator_;
  std::shared_ptr<SteeringEndStops> end_stops_;
};

}  // namespace birkhoff_cart
