#include "birkhoff_cart/core/physics/cart_model.h"

#include "birkhoff_cart/core/integrators/angle_reduction.h"
#include "birkhoff_cart/core/integrators/deterministic_math.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace birkhoff_cart {

CartModel::CartModel(const CartParameters& parameters, InertiaModel inertia_model)
    : parameters_(parameters), inertia_model_(inertia_model) {
  parameters_.validate();
  if (inertia_model_ == InertiaModel::kPaperSpecialCase) {
    if (parameters_.wheelbase != 1.0) {
      std::ostringstream message;
      message << "cart parameter 'wheelbase' must be 1 in the paper's special case (eq. (20) sets "
                 "l = 1), got "
              << parameters_.wheelbase;
      throw std::invalid_argument(message.str());
    }
    inertia_ = ReducedInertia::paper_special_case();
  } else {
    inertia_ = reduced_inertia(parameters_);
    inertia_.validate_positive_definite();
  }
}

// T* and p2 are 2π-periodic in χ: evaluated at χ reduced with its low part (angle_reduction.h).
double CartModel::energy(const CartState& state) const {
  return kinetic_energy(reduced_angle(state.steering_angle, state.steering_angle_low),
                        Vector2<double>(state.forward_speed, state.steering_rate));
}

double CartModel::steering_momentum(const CartState& state) const {
  return momentum(reduced_angle(state.steering_angle, state.steering_angle_low),
                  Vector2<double>(state.forward_speed, state.steering_rate))(1);
}

Eigen::Vector2d CartModel::rear_axle_midpoint(const CartState& state) const {
  return {state.x - parameters_.wheelbase * deterministic::cos(state.heading),
          state.y - parameters_.wheelbase * deterministic::sin(state.heading)};
}

Eigen::Matrix<double, 6, 1> CartModel::constraint_residuals(const CartParameters& p,
                                                           const Eigen::Matrix<double, 8, 1>& q,
                                                           const Eigen::Matrix<double, 8, 1>& v) {
  const double theta = q(2);
  const double chi = q(3);
  const double front = theta + chi;
  const double x_rate = v(0), y_rate = v(1), heading_rate = v(2), steering_rate = v(3);
  const double along_rear = x_rate * deterministic::cos(theta) + y_rate * deterministic::sin(theta);
  const double along_front = x_rate * deterministic::cos(front) + y_rate * deterministic::sin(front);
  const double front_yaw_rate = heading_rate + steering_rate;
  Eigen::Matrix<double, 6, 1> residual;
  residual(0) = -x_rate * deterministic::sin(front) + y_rate * deterministic::cos(front);                       // B no side slip
  residual(1) = -x_rate * deterministic::sin(theta) + y_rate * deterministic::cos(theta) - p.wheelbase * heading_rate;  // A no side slip
  residual(2) = along_rear - p.rear_half_track * heading_rate - p.rear_wheel_radius * v(4);  // wheel 1 rolls
  residual(3) = along_rear + p.rear_half_track * heading_rate - p.rear_wheel_radius * v(5);  // wheel 2 rolls
  residual(4) = along_front - p.front_half_track * front_yaw_rate - p.front_wheel_radius * v(6);  // wheel 3
  residual(5) = along_front + p.front_half_track * front_yaw_rate - p.front_wheel_radius * v(7);  // wheel 4
  return residual;
}

Eigen::Matrix<double, 8, 1> CartModel::coordinate_velocities(const CartState& state) const {
  const CoordinateRates<double> rates = coordinate_rates(
      state.heading, state.steering_angle, Vector2<double>(state.forward_speed, state.steering_rate));
  Eigen::Matrix<double, 8, 1> velocity;
  velocity << rates.x_rate, rates.y_rate, rates.heading_rate, state.steering_rate, rates.wheel_spin_rate[0],
      rates.wheel_spin_rate[1], rates.wheel_spin_rate[2], rates.wheel_spin_rate[3];
  return velocity;
}

double CartModel::max_constraint_residual(const CartState& state) const {
  Eigen::Matrix<double, 8, 1> coordinates;
  coordinates << state.x, state.y, state.heading, state.steering_angle, state.wheel_spin_angle[0],
      state.wheel_spin_angle[1], state.wheel_spin_angle[2], state.wheel_spin_angle[3];
  return constraint_residuals(parameters_, coordinates, coordinate_velocities(state)).cwiseAbs().maxCoeff();
}

}  // namespace birkhoff_cart
