// The closed-form J = ∂ẇ/∂w of the autonomous form (cart_birkhoffian.h darboux_jacobian), which the
// collocation members' Newton matrices use, against forward-mode automatic differentiation of the
// rates themselves: with all six effects on, with the free cart, and with the non-Birkhoffian force
// off (the Birkhoffian part), at random states; and its π1 column is exactly zero (the cyclic
// coordinate the Newton matrix takes out of its block, kronecker_newton.h).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>
#include <vector>

#include "all_effects.h"
#include "birkhoff_cart/core/physics/cart_birkhoffian.h"
#include "birkhoff_cart/core/physics/cart_model.h"
#include "birkhoff_cart/core/physics/effect_library.h"
#include "birkhoff_cart/core/integrators/newton.h"

namespace birkhoff_cart {
namespace {

using Jacobian = Eigen::Matrix<double, kBirkhoffianSize, kBirkhoffianSize>;

using birkhoff_cart_test::all_effect_specs;

/// ∂ẇ/∂w of `system` by AD of darboux_rates at (w, t).
Jacobian jacobian_by_ad(const CartAutonomousBirkhoffian& system, const Eigen::Vector4d& w, double t) {
  using Jet = newton_detail::JacobianJet<kBirkhoffianSize>;
  Eigen::Matrix<Jet, kBirkhoffianSize, 1> w_jet;
  for (int k = 0; k < kBirkhoffianSize; ++k) {
    w_jet(k).value() = w(k);
    w_jet(k).derivatives() = Eigen::Matrix<double, kBirkhoffianSize, 1, Eigen::DontAlign>::Unit(k);
  }
  const auto rate = system.darboux_rates(w_jet, Jet(t));
  Jacobian jacobian;
  for (int k = 0; k < kBirkhoffianSize; ++k) jacobian.row(k) = rate(k).derivatives().transpose();
  return jacobian;
}

/// Random points w = (π1, χ, p1, p2) and times over the range the scenes reach.
std::vector<std::pair<Eigen::Vector4d, double>> random_points(int count) {
  std::mt19937 random(17);
  std::uniform_real_distribution<double> arc(-50.0, 50.0), steering(-1.4, 1.4), momentum(-600.0, 600.0),
      steering_momentum(-60.0, 60.0), time(0.0, 30.0);
  std::vector<std::pair<Eigen::Vector4d, double>> points;
  for (int i = 0; i < count; ++i) {
    points.push_back({Eigen::Vector4d(arc(random), steering(random), momentum(random), steering_momentum(random)),
                      time(random)});
  }
  return points;
}

/// Largest |closed − AD| over the entries, relative to the largest |entry| of the row.
double worst_relative_difference(const Jacobian& closed, const Jacobian& automatic) {
  double worst = 0.0;
  for (int r = 0; r < kBirkhoffianSize; ++r) {
    const double scale = std::max(automatic.row(r).cwiseAbs().maxCoeff(), 1e-300);
    worst = std::max(worst, (closed.row(r) - automatic.row(r)).cwiseAbs().maxCoeff() / scale);
  }
  return worst;
}

constexpr double kAgreement = 1e-12;  // relative, per row [-]

TEST(CartJacobian, ClosedFormEqualsAutomaticDifferentiationWithEveryEffect) {
  const CartModel model{CartParameters{}};
  const EffectSet effects = build_effects(all_effect_specs(), model);
  const CartAutonomousBirkhoffian system(model, effects);
  for (const auto& [w, t] : random_points(50)) {
    const Jacobian closed = system.darboux_jacobian(w, t);
    EXPECT_LT(worst_relative_difference(closed, jacobian_by_ad(system, w, t)), kAgreement) << "w = " << w.transpose();
    EXPECT_TRUE((closed.col(kArcLengthIndex).array() == 0.0).all()) << "no rate reads π1";
  }
}

TEST(CartJacobian, ClosedFormEqualsAutomaticDifferentiationForTheFreeCart) {
  const CartModel model{CartParameters{}};
  const EffectSet effects;
  const CartAutonomousBirkhoffian system(model, effects);
  for (const auto& [w, t] : random_points(50)) {
    EXPECT_LT(worst_relative_difference(system.darboux_jacobian(w, t), jacobian_by_ad(system, w, t)), kAgreement);
  }
}

TEST(CartJacobian, ClosedFormEqualsAutomaticDifferentiationOfTheBirkhoffianPart) {
  const CartModel model{CartParameters{}};
  const EffectSet effects = build_effects(all_effect_specs(), model);
  CartAutonomousBirkhoffian system(model, effects);
  system.set_non_birkhoffian_force_enabled(false);
  for (const auto& [w, t] : random_points(50)) {
    EXPECT_LT(worst_relative_difference(system.darboux_jacobian(w, t), jacobian_by_ad(system, w, t)), kAgreement);
  }
}

}  // namespace
}  // namespace birkhoff_cart
