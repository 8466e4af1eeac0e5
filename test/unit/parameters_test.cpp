// The reduced-inertia coefficients μ, μ1, ν of docs eqs. (2.9)–(2.11) and parameter validation.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "birkhoff_cart/core/physics/cart_model.h"
#include "birkhoff_cart/core/physics/parameters.h"

namespace birkhoff_cart {
namespace {

constexpr double kCoefficientTolerance = 1e-12;  // relative [-]

TEST(ReducedInertia, DefaultCartByHand) {
  // Hand evaluation of eqs. (2.7)–(2.11) for the default cart, term by term.
  const double rear_mass = 140.0 + 2 * 3.0 + 2 * 0.03 / (0.14 * 0.14);
  const double front_mass = 12.0 + 2 * 2.2 + 2 * 0.019 / (0.13 * 0.13);
  const double rear_yaw = 30.0 + 2 * 3.0 * 0.55 * 0.55 + 2 * 0.025 + 2 * 0.03 * 0.55 * 0.55 / (0.14 * 0.14);
  const double front_yaw = 1.0 + 2 * 2.2 * 0.5 * 0.5 + 2 * 0.013 + 2 * 0.019 * 0.5 * 0.5 / (0.13 * 0.13);
  const ReducedInertia inertia = reduced_inertia(CartParameters{});
  EXPECT_NEAR(inertia.mu, rear_mass + front_mass, kCoefficientTolerance * inertia.mu);
  EXPECT_NEAR(inertia.mu1, (rear_yaw + front_yaw) / (1.05 * 1.05) - rear_mass, kCoefficientTolerance * 200);
  EXPECT_NEAR(inertia.nu, front_yaw / 1.05, kCoefficientTolerance * inertia.nu);
  EXPECT_DOUBLE_EQ(inertia.wheelbase, 1.05);
  EXPECT_GT(inertia.smallest_mass_matrix_determinant(), 0.0);
}

TEST(ReducedInertia, PaperPrintedMuUsesTheWrongWheelInertia) {
  // The paper's eq. (19) prints 2 J2 / r2² in μ; there is no J2 among the parameters (the front
  // wheel's spin inertia is J3). With J3 the translational mass is the sum of all masses plus the
  // rolling wheels' equivalent masses J/r².
  CartParameters cart;
  const ReducedInertia inertia = reduced_inertia(cart);
  const double masses = cart.rear_body_mass + 2 * cart.rear_wheel_mass + cart.front_axle_mass + 2 * cart.front_wheel_mass;
  const double rolling = 2 * cart.rear_wheel_spin_inertia / std::pow(cart.rear_wheel_radius, 2) +
                         2 * cart.front_wheel_spin_inertia / std::pow(cart.front_wheel_radius, 2);
  EXPECT_NEAR(inertia.mu, masses + rolling, 1e-12);
}

TEST(CartParameters, RejectsEachNonPositiveOrNonFiniteParameterByName) {
  const std::pair<const char*, double CartParameters::*> fields[] = {
      {"wheelbase", &CartParameters::wheelbase},
      {"rear_half_track", &CartParameters::rear_half_track},
      {"front_half_track", &CartParameters::front_half_track},
      {"rear_wheel_radius", &CartParameters::rear_wheel_radius},
      {"front_wheel_radius", &CartParameters::front_wheel_radius},
      {"rear_body_mass", &CartParameters::rear_body_mass},
      {"rear_body_yaw_inertia", &CartParameters::rear_body_yaw_inertia},
      {"front_axle_mass", &CartParameters::front_axle_mass},
      {"front_axle_yaw_inertia", &CartParameters::front_axle_yaw_inertia},
      {"rear_wheel_mass", &CartParameters::rear_wheel_mass},
      {"rear_wheel_spin_inertia", &CartParameters::rear_wheel_spin_inertia},
      {"rear_wheel_yaw_inertia", &CartParameters::rear_wheel_yaw_inertia},
      {"front_wheel_mass", &CartParameters::front_wheel_mass},
      {"front_wheel_spin_inertia", &CartParameters::front_wheel_spin_inertia},
      {"front_wheel_yaw_inertia", &CartParameters::front_wheel_yaw_inertia},
      {"gravity", &CartParameters::gravity},
  };
  for (const auto& [name, field] : fields) {
    for (const double bad : {0.0, -1.0, std::numeric_limits<double>::quiet_NaN(),
                             std::numeric_limits<double>::infinity()}) {
      CartParameters cart;
      cart.*field = bad;
      try {
        cart.validate();
        ADD_FAILURE() << name << " = " << bad << " was accepted";
      } catch (const std::invalid_argument& error) {
        EXPECT_NE(std::string(error.what()).find(std::string("'") + name + "'"), std::string::npos) << error.what();
      }
    }
  }
}

TEST(CartModel, RefusesThePaperCoefficientsUnlessDeclared) {
  const ReducedInertia paper = ReducedInertia::paper_special_case();
  EXPECT_THROW(paper.validate_positive_definite(), std::invalid_argument);
  CartParameters unit_wheelbase;
  unit_wheelbase.wheelbase = 1.0;
  const CartModel declared(unit_wheelbase, InertiaModel::kPaperSpecialCase);
  EXPECT_DOUBLE_EQ(declared.inertia().mu, 0.0);
  EXPECT_DOUBLE_EQ(declared.inertia().nu, 1.0);
  EXPECT_THROW(CartModel(CartParameters{}, InertiaModel::kPaperSpecialCase), std::invalid_argument);
}

}  // namespace
}  // namespace birkhoff_cart
