// dopri5's work limits (dopri5.h): a tolerance floor tied to machine precision, a bound on the
// internal steps per simulator step, and odeint's real failure signal (step_adjustment_error)
// turned into a StepError that names it.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "birkhoff_cart/core/integrators/diagnostics.h"
#include "birkhoff_cart/core/cart_binding/cart_stepper.h"
#include "birkhoff_cart/core/integrators/dopri5.h"
#include "test_systems.h"

namespace birkhoff_cart {
namespace {

using testing::DampedOscillator;

/// ż = (1/t, 1/t) for t > 0 (0 at t = 0): z = ln t + C is singular at t = 0⁺. From t = 0 the
/// error estimate of a trial step over (0, dt] is dt·Σ(b − b̂)ᵢ/(cᵢ dt), the same for every dt and
/// far above the tolerance: every trial is rejected until odeint gives up.
struct RateSingularAtZero {
  static constexpr int kDimension = 2;
  static constexpr int kPassiveDimension = 1;
  template <class S>
  using Vector = Eigen::Matrix<S, 2, 1>;
  template <class S>
  Vector<S> birkhoffian_gradient(const Vector<S>& /*z*/, const S& t) const {
    const S rate = t > 0.0 ? S(1.0) / t : S(0.0);
    return Vector<S>(rate, rate);
  }
  template <class S>
  Vector<S> birkhoff_functions_time_derivative(const Vector<S>& /*z*/, const S& /*t*/) const {
    return Vector<S>::Zero();
  }
  template <class S>
  Vector<S> non_birkhoffian_force(const Vector<S>& /*z*/, const S& /*t*/) const {
    return Vector<S>::Zero();
  }
  template <class S>
  Eigen::Matrix<S, 2, 2> structure_matrix_inverse(const Vector<S>& /*z*/, const S& /*t*/) const {
    return Eigen::Matrix<S, 2, 2>::Identity();
  }
  template <class S>
  Eigen::Matrix<S, 1, 1> passive_rates(const Vector<S>& z, const S& /*t*/) const {
    return Eigen::Matrix<S, 1, 1>(z(0));
  }
};

TEST(Dopri5Limits, ToleranceBelowTenMachineEpsilonsIsRefused) {
  EXPECT_THROW(DormandPrince5(1e-24), std::invalid_argument);
  EXPECT_THROW(DormandPrince5(1e-16), std::invalid_argument);
  EXPECT_THROW(DormandPrince5(NAN), std::invalid_argument);
  EXPECT_NO_THROW(DormandPrince5(DormandPrince5::kMinTolerance));
  EXPECT_DOUBLE_EQ(DormandPrince5::kMinTolerance, 10.0 * std::numeric_limits<double>::epsilon());
}

TEST(Dopri5Limits, TheFloorToleranceStillRunsAStepInBoundedWork) {
  const DampedOscillator system;
  const DormandPrince5 stepper(DormandPrince5::kMinTolerance);
  Eigen::Vector2d z(1.0, 0.0);
  Eigen::Matrix<double, 1, 1> y(0.0);
  StepStatistics statistics;
  stepper.step(system, z, y, 0.0, 0.01, statistics);  // must neither throw nor run away
  EXPECT_LT(statistics.rhs_evaluations, 7u * DormandPrince5::kMaxInternalSteps);
  EXPECT_TRUE(std::isfinite(z(0)) && std::isfinite(z(1)));
}

TEST(Dopri5Limits, MoreInternalStepsThanTheLimitEndTheStepWithANamedStepError) {
  const DampedOscillator system;
  const DormandPrince5 stepper(1e-12, 10);  // 10 internal steps cannot cover 10 s at 1e-12
  Eigen::Vector2d z(1.0, 0.0);
  Eigen::Matrix<double, 1, 1> y(0.0);
  StepStatistics statistics;
  try {
    stepper.step(system, z, y, 0.0, 10.0, statistics);
    FAIL() << "10 s in 10 internal steps at 1e-12";
  } catch (const StepError& error) {
    EXPECT_NE(std::string(error.what()).find("max_internal_steps = 10"), std::string::npos) << error.what();
  }
  EXPECT_EQ(z(0), 1.0);  // the state is untouched
}

TEST(Dopri5Limits, InternalStepsBelowTheSpacingOfDoublesEndInAStepErrorNotAHang) {
  // At t = 1e15 doubles are 0.125 s apart; the oscillator (period 3.1 s) needs internal steps of
  // ~0.01 s at 1e-10, so t + dt = t and odeint would loop for ever.
  DampedOscillator system;
  system.damping = 0.0;
  const DormandPrince5 stepper(1e-10, 1000);
  Eigen::Vector2d z(1.0, 0.0);
  Eigen::Matrix<double, 1, 1> y(0.0);
  StepStatistics statistics;
  EXPECT_THROW(stepper.step(system, z, y, 1e15, 100.0, statistics), StepError);
}

TEST(Dopri5Limits, OdeintStepAdjustmentErrorBecomesAStepErrorNamingIt) {
  // odeint's failed_step_checker throws step_adjustment_error (a std::runtime_error) after 500
  // rejected trials; the old handler caught only std::overflow_error, so it escaped.
  const RateSingularAtZero system;
  const DormandPrince5 stepper(1e-10);
  Eigen::Vector2d z(1.0, 0.0);
  Eigen::Matrix<double, 1, 1> y(0.0);
  StepStatistics statistics;
  try {
    stepper.step(system, z, y, 0.0, 1e200, statistics);  // 500 rejections (dt ÷ 5 each) from 1e200 stay > 0
    FAIL() << "no failure";
  } catch (const StepError& error) {
    EXPECT_NE(std::string(error.what()).find("step_adjustment_error"), std::string::npos) << error.what();
  }
}

}  // namespace
}  // namespace birkhoff_cart
