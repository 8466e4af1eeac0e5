#include "birkhoff_cart/core/physics/parameters.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace birkhoff_cart {
namespace {

void require_positive(const char* name, double value) {
  if (!std::isfinite(value) || value <= 0.0) {
    std::ostringstream message;
    message << "cart parameter '" << name << "' must be finite and > 0, got " << value;
    throw std::invalid_argument(message.str());
  }
}

}  // namespace

void CartParameters::validate() const {
  const std::pair<const char*, double> named[] = {
      {"wheelbase", wheelbase},
      {"rear_half_track", rear_half_track},
      {"front_half_track", front_half_track},
      {"rear_wheel_radius", rear_wheel_radius},
      {"front_wheel_radius", front_wheel_radius},
      {"rear_body_mass", rear_body_mass},
      {"rear_body_yaw_inertia", rear_body_yaw_inertia},
      {"front_axle_mass", front_axle_mass},
      {"front_axle_yaw_inertia", front_axle_yaw_inertia},
      {"rear_wheel_mass", rear_wheel_mass},
      {"rear_wheel_spin_inertia", rear_wheel_spin_inertia},
      {"rear_wheel_yaw_inertia", rear_wheel_yaw_inertia},
      {"front_wheel_mass", front_wheel_mass},
      {"front_wheel_spin_inertia", front_wheel_spin_inertia},
      {"front_wheel_yaw_inertia", front_wheel_yaw_inertia},
      {"gravity", gravity},
  };
  for (const auto& [name, value] : named) require_positive(name, value);
}

ReducedInertia ReducedInertia::paper_special_case() {
  ReducedInertia inertia;
  inertia.mu = 0.0;
  inertia.mu1 = 0.0;
  inertia.nu = 1.0;
  inertia.wheelbase = 1.0;
  return inertia;
}

double ReducedInertia::smallest_mass_matrix_determinant() const {
  const double at_straight = mu * wheelbase * nu;                      // s² = 0
  const double at_right_angle = (mu + mu1) * wheelbase * nu - nu * nu;  // s² = 1
  return std::min(at_straight, at_right_angle);
}

void ReducedInertia::validate_positive_definite() const {
  if (!(wheelbase * nu > 0.0) || !(smallest_mass_matrix_determinant() > 0.0)) {
    std::ostringstream message;
    message << "reduced inertia (mu=" << mu << ", mu1=" << mu1 << ", nu=" << nu
            << ", wheelbase=" << wheelbase
            << ") gives a mass matrix that is not positive definite for every steering angle "
               "(min det = "
            << smallest_mass_matrix_determinant()
            << "); only the paper's special case may be singular, and a scene must declare it "
               "with 'paper_special_case: true'";
    throw std::invalid_argument(message.str());
  }
}

ReducedInertia reduced_inertia(const CartParameters& p) {
  p.validate();
  const double l = p.wheelbase;
  // Rear assembly: effective translational mass at A and yaw inertia about A   (eq. (2.7)).
  const double rear_mass = p.rear_body_mass + 2.0 * p.rear_wheel_mass +
                           2.0 * p.rear_wheel_spin_inertia / (p.rear_wheel_radius * p.rear_wheel_radius);
  const double rear_yaw_inertia =
      p.rear_body_yaw_inertia + 2.0 * p.rear_wheel_mass * p.rear_half_track * p.rear_half_track +
      2.0 * p.rear_wheel_yaw_inertia +
      2.0 * p.rear_wheel_spin_inertia * p.rear_half_track * p.rear_half_track /
          (p.rear_wheel_radius * p.rear_wheel_radius);
  // Front assembly: effective mass at B and yaw inertia about B   (eq. (2.7)).
  const double front_mass = p.front_axle_mass + 2.0 * p.front_wheel_mass +
                            2.0 * p.front_wheel_spin_inertia / (p.front_wheel_radius * p.front_wheel_radius);
  const double front_yaw_inertia =
      p.front_axle_yaw_inertia + 2.0 * p.front_wheel_mass * p.front_half_track * p.front_half_track +
      2.0 * p.front_wheel_yaw_inertia +
      2.0 * p.front_wheel_spin_inertia * p.front_half_track * p.front_half_track /
          (p.front_wheel_radius * p.front_wheel_radius);
  ReducedInertia inertia;
  inertia.mu = rear_mass + front_mass;                                     // eq. (2.9)
  inertia.mu1 = (rear_yaw_inertia + front_yaw_inertia) / (l * l) - rear_mass;  // eq. (2.10)
  inertia.nu = front_yaw_inertia / l;                                       // eq. (2.11)
  inertia.wheelbase = l;
  return inertia;
}

}  // namespace birkhoff_cart
