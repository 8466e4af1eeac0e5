// The contract every integrator of the registry keeps: observed order by step halving on a system
// with an exact solution and on the cart, determinism, invariants of the free cart, time symmetry of
// the symmetric ones, the finite-value guard and misuse errors. One typed suite over the generic
// steppers of the registry's members (integrator_members.h; Drake / Boost.Odeint style), on the test
// systems, the cart and the example system (the Chaplygin sleigh: order against its closed form,
// energy over a long run, reversal), and the check that its members are the registry's.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <set>
#include <string>
#include <vector>

#include "birkhoff_cart/core/physics/cart_birkhoffian.h"
#include "birkhoff_cart/core/physics/effect_library.h"
#include "birkhoff_cart/core/examples/chaplygin_sleigh.h"
#include "birkhoff_cart/core/cart_binding/cart_stepper.h"
#include "birkhoff_cart/core/integrators/integrator_members.h"
#include "birkhoff_cart/core/scene/scene.h"
#include "generated_docs.h"
#include "registry_members.h"
#include "test_systems.h"

namespace birkhoff_cart {
namespace {

constexpr double kOrderSlack = 0.3;             // |observed − expected order| [-]
constexpr double kSymmetryTolerance = 1e-12;    // |z after +h, −h − z₀| (max-norm) [state units]
constexpr double kLinearInvariantTolerance = 1e-12;  // |p2 − p2₀| / |p2₀| on the free cart [-]
constexpr double kRoundOffAgreement = 1e-12;    // midpoint vs birkhoff2 where the chart is the identity [-]

Scene load(const std::string& name) {
  return load_scene(std::string(BIRKHOFF_CART_SOURCE_DIR) + "/config/scenes/" + name + ".yaml");
}

/// dopri5 and any other member that steps for a local error tolerance instead of at h alone.
template <class Stepper>
constexpr bool kAdaptive = member_kind<Stepper>() == IntegratorKind::kAdaptive;

/// Observed order against nominal: within ±0.3 up to order 4. From order 6 on, the free cart's
/// energy error and the forced cart's state error still fall faster than h^p over the step range
/// that stays above the reference's 1e-13 floor (measured: gauss6 energy 6.57 then 6.05, Kahan–Li 8
/// forced cart 9.0 then 8.3, energy 9.7 then 8.5): there the check is p − 0.3 ≤ observed ≤ p + 2.
void expect_order(double observed, int nominal, const std::string& what) {
  if (nominal <= 4) {
    EXPECT_NEAR(observed, nominal, kOrderSlack) << what;
  } else {
    EXPECT_GE(observed, nominal - kOrderSlack) << what;
    EXPECT_LE(observed, nominal + 2.0) << what;
  }
}

/// Coarsest step counts for the order measurements (then ×2, ×4): the errors must stay in the
/// asymptotic range and well above round-off and the reference's error at every level.
enum class OrderProblem { kDampedOscillator, kForcedCart, kFreeCartEnergy };
int base_steps(int order, OrderProblem problem) {
  switch (problem) {
    case OrderProblem::kDampedOscillator:
      return order == 2 ? 100 : order == 4 ? 25 : order == 6 ? 8 : 4;
    case OrderProblem::kForcedCart:
      return order == 2 ? 100 : order == 4 ? 20 : order == 6 ? 8 : 3;
    case OrderProblem::kFreeCartEnergy:
      return order == 2 ? 200 : order == 4 ? 80 : order == 6 ? 40 : 30;
  }
  return 0;
}

/// Integrates the damped oscillator from t = 0 over `duration` [s] with n equal steps; returns the
/// max-norm error of (q, p, y) against the exact solution.
template <class Stepper>
double damped_oscillator_error(const Stepper& stepper, double duration, int steps) {
  testing::DampedOscillator oscillator;
  const Eigen::Vector2d z0(1.0, 0.5);
  Eigen::Vector2d z = z0;
  Eigen::Matrix<double, 1, 1> y = Eigen::Matrix<double, 1, 1>::Zero();
  StepStatistics statistics;
  const double h = duration / steps;
  for (int k = 0; k < steps; ++k) stepper.step(oscillator, z, y, k * h, h, statistics);
  Eigen::Vector2d exact;
  double exact_y = 0.0;
  oscillator.exact(0.0, z0, 0.0, duration, exact, exact_y);
  return std::max((z - exact).cwiseAbs().maxCoeff(), std::abs(y(0) - exact_y));
}

/// Max-norm difference of the cart states' coordinates and quasi-velocities.
double state_difference(const CartState& a, const CartState& b) {
  const double differences[] = {a.x - b.x,
                                a.y - b.y,
                                a.heading - b.heading,
                                a.steering_angle - b.steering_angle,
                                a.arc_length - b.arc_length,
                                a.forward_speed - b.forward_speed,
                                a.steering_rate - b.steering_rate,
                                a.wheel_spin_angle[0] - b.wheel_spin_angle[0],
                                a.wheel_spin_angle[3] - b.wheel_spin_angle[3],
                                a.applied_work - b.applied_work,
                                a.steering_impulse - b.steering_impulse};
  double largest = 0.0;
  for (double d : differences) largest = std::max(largest, std::abs(d));
  return largest;
}

/// A scene run by the registry's CartStepper with n steps of size h (time set to t₀ + k h).
CartState run_cart(const Scene& scene, const IntegratorSettings& settings, double h, int steps,
                   StepStatistics* statistics_out = nullptr) {
  const CartModel model(scene.cart,
                        scene.paper_special_case ? InertiaModel::kPaperSpecialCase : InertiaModel::kPhysical);
  const EffectSet effects = build_effects(scene.effects, model);
  std::unique_ptr<CartStepper> stepper = make_cart_stepper(settings, model, effects);
  CartState state = scene.initial_state;
  StepStatistics statistics;
  for (int k = 1; k <= steps; ++k) {
    stepper->step(state, h, statistics);
    state.time = scene.initial_state.time + k * h;
  }
  if (statistics_out) *statistics_out = statistics;
  return state;
}

IntegratorSettings settings_for(const std::string& name, BirkhoffianForm form = BirkhoffianForm::kAutonomous) {
  IntegratorSettings settings;
  settings.name = name;
  settings.birkhoffian_form = form;
  return settings;
}

template <class Stepper>
class IntegratorContract : public ::testing::Test {
 protected:
  const Stepper stepper_ = birkhoff_cart_test::default_stepper<Stepper>();  ///< built as the registry builds it
};

// Every member of the registry (integrator_members.h), under its own name.
TYPED_TEST_SUITE(IntegratorContract, birkhoff_cart_test::RegistrySteppers, birkhoff_cart_test::StepperNames);

// The registry makes it under its own name. Its order() and symmetric() flags are checked against
// measured behaviour (observed order, reversibility) in registry_properties_test.cpp: compared here
// with TypeParam::kOrder they would be compared with the very constants the adapter returns.
TYPED_TEST(IntegratorContract, RegistryKnowsIt) {
  const std::vector<std::string> names = integrator_names();
  ASSERT_NE(std::find(names.begin(), names.end(), TypeParam::name()), names.end());
  const Scene scene = load("free_coast");
  const CartModel model(scene.cart);
  const EffectSet effects;
  const std::unique_ptr<CartStepper> stepper = make_cart_stepper(settings_for(TypeParam::name()), model, effects);
  EXPECT_EQ(stepper->name(), TypeParam::name());
}

TYPED_TEST(IntegratorContract, ObservedOrderOnDampedOscillator) {
  constexpr double kDuration = 2.0;  // [s]
  if constexpr (kAdaptive<TypeParam>) {
    // dopri5: the error decreases with the tolerance (same simulator step h = 0.1 s).
    std::vector<double> errors;
    for (double tolerance : {1e-6, 1e-8, 1e-10, 1e-12}) {
      errors.push_back(damped_oscillator_error(TypeParam(tolerance), kDuration, 20));
    }
    for (std::size_t i = 1; i < errors.size(); ++i) {
      std::printf("%s damped oscillator: tolerance 1e-%zu error %.3e\n", TypeParam::name(), 4 + 2 * i, errors[i]);
      EXPECT_LT(errors[i], errors[i - 1]);
    }
    EXPECT_LT(errors.back(), 1e-10);
  } else {
    const int steps = base_steps(TypeParam::kOrder, OrderProblem::kDampedOscillator);
    const double e1 = damped_oscillator_error(this->stepper_, kDuration, steps);
    const double e2 = damped_oscillator_error(this->stepper_, kDuration, 2 * steps);
    const double e3 = damped_oscillator_error(this->stepper_, kDuration, 4 * steps);
    const double order12 = std::log2(e1 / e2), order23 = std::log2(e2 / e3);
    std::printf("%s damped oscillator: errors %.3e %.3e %.3e, observed orders %.3f %.3f\n", TypeParam::name(), e1,
                e2, e3, order12, order23);
    EXPECT_NEAR(order12, TypeParam::kOrder, kOrderSlack);
    EXPECT_NEAR(order23, TypeParam::kOrder, kOrderSlack);
  }
}

TYPED_TEST(IntegratorContract, ObservedOrderOnForcedCartInBothRepresentations) {
  // sine_steer_torque (χ₀ = 0, ω1 = 5 m/s, τ = 3 cos(π t) N·m) over 1 s; reference: dopri5 at 1e-13.
  const Scene scene = load("sine_steer_torque");
  constexpr double kDuration = 1.0;  // [s]
  IntegratorSettings reference_settings = settings_for("dopri5");
  reference_settings.tolerance = 1e-13;
  const CartState reference = run_cart(scene, reference_settings, 1e-2, 100);
  for (BirkhoffianForm form : {BirkhoffianForm::kAutonomous, BirkhoffianForm::kPaper}) {
    if constexpr (kAdaptive<TypeParam>) {
      std::vector<double> errors;
      for (double tolerance : {1e-6, 1e-8, 1e-10}) {
        IntegratorSettings settings = settings_for(TypeParam::name(), form);
        settings.tolerance = tolerance;
        errors.push_back(state_difference(run_cart(scene, settings, 0.05, 20), reference));
      }
      std::printf("%s cart (%s): errors %.3e %.3e %.3e for tolerances 1e-6, 1e-8, 1e-10\n", TypeParam::name(), to_string(form),
                  errors[0], errors[1], errors[2]);
      EXPECT_LT(errors[1], errors[0]);
      EXPECT_LT(errors[2], errors[1]);
    } else {
      double errors[3];
      for (int level = 0; level < 3; ++level) {
        const int steps = base_steps(TypeParam::kOrder, OrderProblem::kForcedCart) << level;
        errors[level] = state_difference(run_cart(scene, settings_for(TypeParam::name(), form),
                                                  kDuration / steps, steps),
                                         reference);
      }
      const double order12 = std::log2(errors[0] / errors[1]), order23 = std::log2(errors[1] / errors[2]);
      std::printf("%s cart (%s): errors %.3e %.3e %.3e, observed orders %.3f %.3f\n", TypeParam::name(),
                  to_string(form), errors[0], errors[1], errors[2], order12, order23);
      expect_order(order12, TypeParam::kOrder, to_string(form));
      expect_order(order23, TypeParam::kOrder, to_string(form));
    }
  }
}

TYPED_TEST(IntegratorContract, TwoRunsAreBitIdentical) {
  const Scene scene = load("drive_rr_drag");  // all the loads that have state-dependent Jacobians
  StepStatistics first_statistics, second_statistics;
  const CartState first = run_cart(scene, settings_for(TypeParam::name()), 1e-2, 300, &first_statistics);
  const CartState second = run_cart(scene, settings_for(TypeParam::name()), 1e-2, 300, &second_statistics);
  EXPECT_EQ(std::memcmp(&first, &second, sizeof(CartState)), 0);
  EXPECT_EQ(first_statistics.rhs_evaluations, second_statistics.rhs_evaluations);
  EXPECT_EQ(first_statistics.steps, 300u);
  EXPECT_GT(first_statistics.rhs_evaluations, 300u);
}

TYPED_TEST(IntegratorContract, FreeCartInvariants) {
  // jackknife_whirl (χ₀ = 1.2, ω1 = 2, ω2 = 1.2, no loads) over 2 s: the energy error shrinks at the
  // method's order; p2 is a linear invariant (ṗ2 = Q2 = 0) kept by every method to round-off.
  const Scene scene = load("jackknife_whirl");
  const CartModel model(scene.cart);
  const double energy0 = model.energy(scene.initial_state);
  const double p2_0 = model.steering_momentum(scene.initial_state);
  constexpr double kDuration = 2.0;  // [s]
  auto run = [&](const IntegratorSettings& settings, int steps, double& energy_error, double& p2_error) {
    const EffectSet effects;
    std::unique_ptr<CartStepper> stepper = make_cart_stepper(settings, model, effects);
    CartState state = scene.initial_state;
    StepStatistics statistics;
    energy_error = p2_error = 0.0;
    const double h = kDuration / steps;
    for (int k = 1; k <= steps; ++k) {
      stepper->step(state, h, statistics);
      state.time = k * h;
      energy_error = std::max(energy_error, std::abs(model.energy(state) - energy0) / energy0);
      p2_error = std::max(p2_error, std::abs(model.steering_momentum(state) - p2_0) / std::abs(p2_0));
    }
  };
  if constexpr (kAdaptive<TypeParam>) {
    std::vector<double> energy_errors;
    for (double tolerance : {1e-6, 1e-8, 1e-10}) {
      IntegratorSettings settings = settings_for(TypeParam::name());
      settings.tolerance = tolerance;
      double energy_error, p2_error;
      run(settings, 40, energy_error, p2_error);
      energy_errors.push_back(energy_error);
      EXPECT_LE(p2_error, kLinearInvariantTolerance);
    }
    std::printf("%s free cart: max |dT*/T*| %.3e %.3e %.3e for tolerances 1e-6, 1e-8, 1e-10\n", TypeParam::name(),
                energy_errors[0], energy_errors[1], energy_errors[2]);
    EXPECT_LT(energy_errors[1], energy_errors[0]);
    EXPECT_LT(energy_errors[2], energy_errors[1]);
  } else {
    double energy_errors[3], p2_errors[3];
    for (int level = 0; level < 3; ++level) {
      run(settings_for(TypeParam::name()), base_steps(TypeParam::kOrder, OrderProblem::kFreeCartEnergy) << level,
          energy_errors[level], p2_errors[level]);
      EXPECT_LE(p2_errors[level], kLinearInvariantTolerance);
    }
    const double order12 = std::log2(energy_errors[0] / energy_errors[1]);
    const double order23 = std::log2(energy_errors[1] / energy_errors[2]);
    std::printf("%s free cart: max |dT*/T*| %.3e %.3e %.3e (orders %.3f %.3f), max |dp2/p2| %.3e\n",
                TypeParam::name(), energy_errors[0], energy_errors[1], energy_errors[2], order12, order23,
                p2_errors[2]);
    expect_order(order12, TypeParam::kOrder, "free cart energy");
    expect_order(order23, TypeParam::kOrder, "free cart energy");
  }
}

TYPED_TEST(IntegratorContract, ForwardThenBackwardStepReturnsOnlyForSymmetricMethods) {
  // A step of +h then one of −h from tₖ₊₁: the identity for a symmetric method (to round-off), an
  // O(h^{p+1}) defect otherwise, on the damped oscillator and on the forced cart (rep (b)).
  testing::DampedOscillator oscillator;
  const Eigen::Vector2d z0(1.0, 0.5);
  Eigen::Vector2d z = z0;
  Eigen::Matrix<double, 1, 1> y = Eigen::Matrix<double, 1, 1>::Zero();
  StepStatistics statistics;
  constexpr double kStep = 0.1;  // [s]
  this->stepper_.step(oscillator, z, y, 0.3, kStep, statistics);
  this->stepper_.step(oscillator, z, y, 0.3 + kStep, -kStep, statistics);
  const double oscillator_defect = std::max((z - z0).cwiseAbs().maxCoeff(), std::abs(y(0)));

  const Scene scene = load("sine_steer_torque");
  const CartModel model(scene.cart);
  const EffectSet effects = build_effects(scene.effects, model);
  CartAutonomousBirkhoffian cart(model, effects);
  CartState start = scene.initial_state;
  start.steering_angle = 0.4;
  start.steering_rate = -0.7;
  const CartBirkhoffianPoint point0 = cart.to_birkhoffian(start);
  CartBirkhoffianPoint point = point0;
  this->stepper_.step(cart, point.z, point.y, 0.3, kStep, statistics);
  this->stepper_.step(cart, point.z, point.y, 0.3 + kStep, -kStep, statistics);
  const double cart_defect = std::max((point.z - point0.z).cwiseAbs().maxCoeff(),
                                      (point.y - point0.y).cwiseAbs().maxCoeff());
  std::printf("%s: +h/-h defect %.3e (oscillator), %.3e (cart)\n", TypeParam::name(), oscillator_defect, cart_defect);
  if (TypeParam::kSymmetric) {
    EXPECT_LE(oscillator_defect, kSymmetryTolerance);
    EXPECT_LE(cart_defect, kSymmetryTolerance);
  } else if (!kAdaptive<TypeParam>) {  // (dopri5's defect is at its tolerance: not informative)
    EXPECT_GT(oscillator_defect, 1e3 * kSymmetryTolerance);
    EXPECT_GT(cart_defect, 1e3 * kSymmetryTolerance);
  }
}

TYPED_TEST(IntegratorContract, NonFiniteValuesAreCaughtAndTheStateIsKept) {
  // The paper's special case on χ = 0, where M(χ) = [[0, sin χ], [sin χ, 1]] is exactly singular
  // (sin 0 = 0 in floating point, unlike sin π): ω = M⁻¹ p is not finite.
  Scene scene = load("paper_special");
  const CartModel model(scene.cart, InertiaModel::kPaperSpecialCase);
  const EffectSet effects;
  std::unique_ptr<CartStepper> stepper = make_cart_stepper(settings_for(TypeParam::name()), model, effects);
  CartState state = scene.initial_state;
  state.steering_angle = 0.0;
  const CartState before = state;
  StepStatistics statistics;
  EXPECT_THROW(stepper->step(state, 1e-3, statistics), StepError);
  EXPECT_EQ(std::memcmp(&state, &before, sizeof(CartState)), 0);
  EXPECT_EQ(statistics.steps, 0u);

  // A NaN in the state, on the physical cart.
  const Scene free_scene = load("free_coast");
  const CartModel free_model(free_scene.cart);
  std::unique_ptr<CartStepper> free_stepper = make_cart_stepper(settings_for(TypeParam::name()), free_model, effects);
  CartState broken = free_scene.initial_state;
  broken.forward_speed = std::nan("");
  try {
    free_stepper->step(broken, 1e-3, statistics);
    ADD_FAILURE() << "a NaN forward speed was stepped without error";
  } catch (const StepError& error) {
    EXPECT_NE(std::string(error.what()).find("t = 0"), std::string::npos) << error.what();
  }
  EXPECT_TRUE(std::isnan(broken.forward_speed));
  EXPECT_EQ(broken.time, 0.0);
}

TYPED_TEST(IntegratorContract, RejectsBadStepSizes) {
  const Scene scene = load("free_coast");
  const CartModel model(scene.cart);
  const EffectSet effects;
  IntegratorSettings settings = settings_for(TypeParam::name());
  std::unique_ptr<CartStepper> stepper = make_cart_stepper(settings, model, effects);
  CartState state = scene.initial_state;
  StepStatistics statistics;
  for (double bad : {0.0, -1e-3, std::nan(""), std::numeric_limits<double>::infinity()}) {
    EXPECT_THROW(stepper->step(state, bad, statistics), std::invalid_argument) << bad;
    settings.step_size = bad;
    EXPECT_THROW(make_cart_stepper(settings, model, effects), std::invalid_argument) << bad;
  }
  EXPECT_EQ(state.time, scene.initial_state.time);
}

// ---------------------------------------------------------------------------------------------
// The example system (include/birkhoff_cart/core/examples/chaplygin_sleigh.h): the same contract on
// a nonholonomic system the members were not written for, through their generic step() alone.

constexpr double kSleighDuration = 3.0;       // order runs [s]
constexpr double kSleighLongRun = 2000.0;     // energy run [s]
constexpr double kSleighLongStep = 0.05;      // its step [s]
constexpr double kSleighEnergyRoundOff = 1e-12;  // |E − E₀| / E₀ kept by the symmetric members [-]

/// Backing up at 0.4 m/s while turning at 2 rad/s: through v = 0 into the turn and out (S.3).
Eigen::Vector4d sleigh_start(const ChaplyginSleigh& sleigh) { return sleigh.state(0.1, 0.3, -0.4, 2.0); }

/// n steps of duration/n from (z₀, y = 0) at t = 0; the largest relative energy error on the way.
template <class Stepper>
Eigen::Vector4d run_sleigh(const Stepper& stepper, const ChaplyginSleigh& sleigh, const Eigen::Vector4d& z0,
                           double duration, int steps, double* energy_error = nullptr) {
  Eigen::Vector4d z = z0;
  Eigen::Vector2d y = Eigen::Vector2d::Zero();
  StepStatistics statistics;
  const double energy0 = sleigh.hamiltonian(z0);
  const double h = duration / steps;
  double largest = 0.0;
  for (int k = 0; k < steps; ++k) {
    stepper.step(sleigh, z, y, k * h, h, statistics);
    largest = std::max(largest, std::abs(sleigh.hamiltonian(z) - energy0) / energy0);
  }
  if (energy_error) *energy_error = largest;
  return z;
}

// docs/integrators.md's table of the sleigh ("measured, every registry member") states what these
// tests measure: each typed test checks its member's figure there. A row is found by its test's
// name in its first cell; a member's figures are those of the group naming it ("3.97–4.00
// (`birkhoff_gauss4`, …)"), or the figure after its name; the symmetric members share a bound.
const char kSleighPage[] = "docs/integrators.md";
constexpr double kStatedOrder = 0.005;  // the page's orders are to two decimals [-]
constexpr double kStatedFigure = 0.06;  // relative, a two-digit figure [-]

std::string sleigh_row(const std::string& test) {
  return birkhoff_cart_test::line_after(kSleighPage, "`" + test + "`) | ");
}

/// The first figure after `marker` in `row`; NaN when the row lacks the marker.
double figure_after(const std::string& row, const std::string& marker) {
  const auto at = row.find(marker);
  const std::vector<double> figures =
      at == std::string::npos ? std::vector<double>{} : birkhoff_cart_test::figures_in(row.substr(at + marker.size()));
  return figures.empty() ? std::numeric_limits<double>::quiet_NaN() : figures.front();
}

/// The member's measured `value` is what the sleigh table's `row` states for it: within the
/// symmetric members' bound (after "symmetric members ≤ "), or, for another member, within 6 % of the
/// figure after its name.
void expect_sleigh_figure(const std::string& row, const std::string& member, bool symmetric, double value) {
  if (symmetric) {
    const double bound = figure_after(row, "symmetric members ≤ ");
    EXPECT_LE(value, bound) << kSleighPage << " states the symmetric members' bound " << bound << " in: " << row;
  } else {
    const double stated = figure_after(row, "`" + member + "` ");
    EXPECT_NEAR(value, stated, kStatedFigure * value) << kSleighPage << " states " << stated << " for " << member
                                                      << " in: " << row;
  }
}

int sleigh_base_steps(int order) { return order == 2 ? 100 : order == 4 ? 30 : order == 6 ? 12 : 8; }

TYPED_TEST(IntegratorContract, ObservedOrderOnTheChaplyginSleigh) {
  // Against the closed form (S.3) over 3 s, in the autonomous form (γ = 0) and the paper's eᵗ form
  // (γ = 1, a time-dependent chart).
  for (double gamma : {0.0, 1.0}) {
    ChaplyginSleighParameters parameters;
    parameters.conformal_rate = gamma;
    const ChaplyginSleigh sleigh(parameters);
    const Eigen::Vector4d z0 = sleigh_start(sleigh);
    const Eigen::Vector4d exact = ChaplyginSleighMotion(sleigh, z0, 0.0).at(kSleighDuration, sleigh);
    auto error_of = [&](const TypeParam& stepper, int steps) {
      return (run_sleigh(stepper, sleigh, z0, kSleighDuration, steps) - exact).cwiseAbs().maxCoeff();
    };
    if constexpr (kAdaptive<TypeParam>) {
      const double e1 = error_of(TypeParam(1e-6), 30), e2 = error_of(TypeParam(1e-8), 30), e3 = error_of(TypeParam(1e-10), 30);
      std::printf("%s sleigh (gamma %g): errors %.3e %.3e %.3e for tolerances 1e-6, 1e-8, 1e-10\n", TypeParam::name(),
                  gamma, e1, e2, e3);
      EXPECT_LT(e2, e1);
      EXPECT_LT(e3, e2);
    } else {
      const int steps = sleigh_base_steps(TypeParam::kOrder);
      const double e1 = error_of(this->stepper_, steps), e2 = error_of(this->stepper_, 2 * steps),
                   e3 = error_of(this->stepper_, 4 * steps);
      const double order12 = std::log2(e1 / e2), order23 = std::log2(e2 / e3);
      std::printf("%s sleigh (gamma %g): errors %.3e %.3e %.3e, observed orders %.3f %.3f\n", TypeParam::name(), gamma,
                  e1, e2, e3, order12, order23);
      expect_order(order12, TypeParam::kOrder, "sleigh");
      expect_order(order23, TypeParam::kOrder, "sleigh");
      const std::vector<double> stated =
          birkhoff_cart_test::group_figures(sleigh_row("ObservedOrderOnTheChaplyginSleigh"), TypeParam::name());
      ASSERT_FALSE(stated.empty()) << kSleighPage << "'s sleigh table states no order for " << TypeParam::name();
      for (double order : {order12, order23}) {
        EXPECT_GE(order, stated.front() - kStatedOrder) << kSleighPage << " states " << stated.front() << " for " << TypeParam::name();
        EXPECT_LE(order, stated.back() + kStatedOrder) << kSleighPage << " states " << stated.back() << " for " << TypeParam::name();
      }
    }
  }
}

TYPED_TEST(IntegratorContract, ChaplyginSleighEnergyOverALongRun) {
  // 2000 s at h = 0.05 s (40 000 steps) through the turn and the glide: the energy, a quadratic
  // invariant, is kept to round-off by the symmetric members (Gauss collocation and the midpoint
  // compositions keep every quadratic invariant) and stays bounded, not drifting, over the run; the
  // others miss it by their local errors.
  const ChaplyginSleigh sleigh;
  const Eigen::Vector4d z0 = sleigh_start(sleigh);
  const int steps = static_cast<int>(kSleighLongRun / kSleighLongStep);
  double energy_error = 0.0;
  run_sleigh(this->stepper_, sleigh, z0, kSleighLongRun, steps, &energy_error);
  std::printf("%s sleigh over %g s: max |dE/E| %.3e\n", TypeParam::name(), kSleighLongRun, energy_error);
  expect_sleigh_figure(sleigh_row("ChaplyginSleighEnergyOverALongRun"), TypeParam::name(), TypeParam::kSymmetric,
                       energy_error);
  if (TypeParam::kSymmetric) {
    EXPECT_LE(energy_error, kSleighEnergyRoundOff);
  } else {
    EXPECT_GT(energy_error, 1e3 * std::numeric_limits<double>::epsilon());
    EXPECT_LE(energy_error, 1e-3);
  }
}

TYPED_TEST(IntegratorContract, ChaplyginSleighIsReversedOnlyBySymmetricMembers) {
  // The sleigh is reversible under R: p ↦ −p (positions kept): ż = f(z) with R f(R z) = −f(z).
  // A symmetric member's map is R-reversible: R Φⁿ R Φⁿ = id to round-off; another misses by
  // O(n h^{p+1}) (dopri5's miss is at its tolerance: not informative).
  const ChaplyginSleigh sleigh;
  const Eigen::Vector4d z0 = sleigh_start(sleigh);
  const auto flip = [](Eigen::Vector4d z) {
    z(kSleighForwardMomentum) = -z(kSleighForwardMomentum);
    z(kSleighAngularMomentum) = -z(kSleighAngularMomentum);
    return z;
  };
  constexpr int kSteps = 20;
  const Eigen::Vector4d back = flip(run_sleigh(this->stepper_, sleigh, flip(run_sleigh(this->stepper_, sleigh, z0, 2.0, kSteps)),
                                               2.0, kSteps));
  const double defect = (back - z0).cwiseAbs().maxCoeff() / std::max(1.0, z0.cwiseAbs().maxCoeff());
  std::printf("%s sleigh: reversal defect %.3e\n", TypeParam::name(), defect);
  if (!kAdaptive<TypeParam>) {
    expect_sleigh_figure(sleigh_row("ChaplyginSleighIsReversedOnlyBySymmetricMembers"), TypeParam::name(),
                         TypeParam::kSymmetric, defect);
  }
  if (TypeParam::kSymmetric) {
    EXPECT_LE(defect, kSymmetryTolerance);
  } else if (!kAdaptive<TypeParam>) {
    EXPECT_GT(defect, 1e3 * kSymmetryTolerance);
  }
}

TEST(IntegratorRegistry, TheTypedSuitesRunOverEveryMember) {
  // The typed suites (this one and k_symplectic_test) take their members from
  // integrator_members.h: they are the registry's, in its order, each named once.
  const std::vector<std::string> tested = birkhoff_cart_test::stepper_names<IntegratorMemberTypes>();
  EXPECT_EQ(tested, integrator_names());
  EXPECT_EQ(std::set<std::string>(tested.begin(), tested.end()).size(), tested.size());
  EXPECT_GE(tested.size(), 12u);
  // The Birkhoffian ones (K(z,t)-symplectic tests) are exactly the rows of a Birkhoffian kind.
  std::vector<std::string> birkhoffian_rows;
  for (const IntegratorEntry& row : integrator_registry()) {
    if (is_birkhoffian(row.kind)) birkhoffian_rows.emplace_back(row.name);
  }
  EXPECT_EQ(birkhoff_cart_test::stepper_names<birkhoff_cart_test::BirkhoffianMemberTypes>(), birkhoffian_rows);
  EXPECT_EQ(birkhoffian_rows.size(), 8u);
}

TEST(IntegratorRegistry, UnknownNameListsTheKnownOnes) {
  const CartModel model{CartParameters{}};
  const EffectSet effects;
  try {
    make_cart_stepper(settings_for("euler"), model, effects);
    FAIL() << "unknown integrator accepted";
  } catch (const std::invalid_argument& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("euler"), std::string::npos) << message;
    for (const std::string& name : integrator_names()) EXPECT_NE(message.find(name), std::string::npos) << message;
  }
  EXPECT_THROW(parse_birkhoffian_form("hamiltonian"), std::invalid_argument);  // no such form reaches the registry
}

TEST(ImplicitMidpoint, CoincidesWithBirkhoff2WhereTheChartIsTheIdentity) {
  // Rep (b): K = K₀ and D = identity, so birkhoff2 is the implicit midpoint rule in z.
  const Scene scene = load("drive_rr_drag");
  IntegratorSettings midpoint = settings_for("midpoint"), birkhoff2 = settings_for("birkhoff2");
  const CartState by_midpoint = run_cart(scene, midpoint, 1e-2, 200);
  const CartState by_birkhoff2 = run_cart(scene, birkhoff2, 1e-2, 200);
  const double difference = state_difference(by_midpoint, by_birkhoff2);
  std::printf("midpoint vs birkhoff2, rep (b), 200 steps: %.3e\n", difference);
  EXPECT_LE(difference, kRoundOffAgreement * std::max(1.0, std::abs(by_birkhoff2.arc_length)));
}

TEST(ImplicitMidpoint, DiffersFromBirkhoff2WhereTheChartIsNotTheIdentity) {
  // Damped oscillator (K = e^{γt} K₀) and the cart's rep (a): midpoint in z ≠ midpoint in w.
  const ImplicitMidpoint midpoint(NewtonSettings{});
  const BirkhoffSymplectic2 birkhoff2(NewtonSettings{});
  testing::DampedOscillator oscillator;
  Eigen::Vector2d z_midpoint(1.0, 0.5), z_birkhoff(1.0, 0.5);
  Eigen::Matrix<double, 1, 1> y_midpoint = Eigen::Matrix<double, 1, 1>::Zero(), y_birkhoff = y_midpoint;
  StepStatistics statistics;
  midpoint.step(oscillator, z_midpoint, y_midpoint, 0.0, 0.1, statistics);
  birkhoff2.step(oscillator, z_birkhoff, y_birkhoff, 0.0, 0.1, statistics);
  const double oscillator_difference = (z_midpoint - z_birkhoff).cwiseAbs().maxCoeff();

  const Scene scene = load("drive_rr_drag");
  const double cart_difference = state_difference(run_cart(scene, settings_for("midpoint", BirkhoffianForm::kPaper), 1e-2, 200),
                                                  run_cart(scene, settings_for("birkhoff2", BirkhoffianForm::kPaper), 1e-2, 200));
  std::printf("midpoint vs birkhoff2: %.3e (oscillator, one step), %.3e (cart rep (a), 200 steps)\n",
              oscillator_difference, cart_difference);
  EXPECT_GT(oscillator_difference, 1e-6);
  EXPECT_GT(cart_difference, 1e-8);
}

}  // namespace
}  // namespace birkhoff_cart
