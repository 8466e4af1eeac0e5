// The paper's own test (its §4, special case μ = μ1 = 0, ν = 1, l = 1): from t₀ = π/2 with
// χ = π/2, ω1 = 1, ω2 = 1, π1 = 1, the exact solution is χ = t, ω1 = 1/sin t, π1 = 1 + ln tan(t/2)
// (docs eq. (3.9)). Integrated to t = π − 0.05 s (ω1 = 20 m/s there, the solution steepening
// towards the singularity at χ = π) with birkhoff2 (both representations) and rk2.
//
// What is asserted is what the mathematics guarantees for 2nd-order one-step methods on a smooth
// solution: the global error is e(h) = E h² + O(h³) for fixed E, so halving h divides the error by
// ≈ 4 (observed order 2 ± 0.3), and e(h) ≤ C h². C is not a free tolerance: C = 2 · e(2h)/(2h)², the
// error constant measured on the coarser run, doubled; e(h) ≤ C h² holds iff the error constant
// e/h² has not grown as h halved, i.e. the runs are in the asymptotic regime 2nd order promises.
// Which method is more accurate is printed, not asserted: nothing guarantees an ordering of their
// error constants.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "birkhoff_cart/core/physics/cart_model.h"
#include "birkhoff_cart/core/physics/effects.h"
#include "birkhoff_cart/core/cart_binding/cart_stepper.h"
#include "birkhoff_cart/core/scene/scene.h"

namespace birkhoff_cart {
namespace {

constexpr double kEndTime = M_PI - 0.05;  // [s]
constexpr double kOrderSlack = 0.3;       // [-]
constexpr double kConstantGrowth = 2.0;   // allowed growth of e(h)/h² from h' = 2h to h [-]

struct PaperErrors {
  double arc_length = 0.0;     ///< |π1 − π1_exact| / |π1_exact| at the end [-]
  double forward_speed = 0.0;  ///< |ω1 − ω1_exact| / |ω1_exact| at the end [-]
};

/// Whole steps of h from t₀ and one final partial step that lands on kEndTime exactly.
PaperErrors run(const std::string& integrator, BirkhoffianForm form, double h) {
  const Scene scene = load_scene(std::string(BIRKHOFF_CART_SOURCE_DIR) + "/config/scenes/paper_special.yaml");
  const CartModel model(scene.cart, InertiaModel::kPaperSpecialCase);
  const EffectSet effects;
  IntegratorSettings settings = scene.integrator;
  settings.name = integrator;
  settings.birkhoffian_form = form;
  settings.step_size = h;
  std::unique_ptr<CartStepper> stepper = make_cart_stepper(settings, model, effects);
  CartState state = scene.initial_state;
  const double t0 = state.time;
  StepStatistics statistics;
  const long whole_steps = static_cast<long>(std::floor((kEndTime - t0) / h));
  for (long k = 1; k <= whole_steps; ++k) {
    stepper->step(state, h, statistics);
    state.time = t0 + static_cast<double>(k) * h;
  }
  const double remainder = kEndTime - state.time;
  if (remainder > 1e-12) stepper->step(state, remainder, statistics);
  state.time = kEndTime;
  const double exact_arc_length = 1.0 + std::log(std::tan(0.5 * kEndTime));  // π1 = 1 + ln tan(t/2) [m]
  const double exact_forward_speed = 1.0 / std::sin(kEndTime);                 // ω1 = 1/sin t [m/s]
  PaperErrors errors;
  errors.arc_length = std::abs(state.arc_length - exact_arc_length) / std::abs(exact_arc_length);
  errors.forward_speed = std::abs(state.forward_speed - exact_forward_speed) / exact_forward_speed;
  return errors;
}

struct Case {
  std::string integrator;
  BirkhoffianForm form;
};

class PaperCase : public ::testing::TestWithParam<Case> {};

TEST_P(PaperCase, SecondOrderErrorAgainstTheAnalyticSolution) {
  const Case& c = GetParam();
  const PaperErrors coarse = run(c.integrator, c.form, 2e-3);
  const PaperErrors nominal = run(c.integrator, c.form, 1e-3);
  const PaperErrors fine = run(c.integrator, c.form, 5e-4);
  std::printf("%s (%s) at t = pi - 0.05: h = 1e-3: pi1 relative error %.3e, omega1 relative error %.3e\n",
              c.integrator.c_str(), to_string(c.form), nominal.arc_length, nominal.forward_speed);
  const double pi1_orders[2] = {std::log2(coarse.arc_length / nominal.arc_length),
                                std::log2(nominal.arc_length / fine.arc_length)};
  const double omega1_orders[2] = {std::log2(coarse.forward_speed / nominal.forward_speed),
                                   std::log2(nominal.forward_speed / fine.forward_speed)};
  std::printf("%s (%s): pi1 errors %.3e %.3e %.3e (orders %.3f %.3f); omega1 errors %.3e %.3e %.3e "
              "(orders %.3f %.3f)\n",
              c.integrator.c_str(), to_string(c.form), coarse.arc_length, nominal.arc_length, fine.arc_length,
              pi1_orders[0], pi1_orders[1], coarse.forward_speed, nominal.forward_speed, fine.forward_speed,
              omega1_orders[0], omega1_orders[1]);
  for (int i = 0; i < 2; ++i) {
    EXPECT_NEAR(pi1_orders[i], 2.0, kOrderSlack);
    EXPECT_NEAR(omega1_orders[i], 2.0, kOrderSlack);
  }
  // e(h) ≤ C h² with C = kConstantGrowth · e(2h)/(2h)².
  constexpr double h = 1e-3;  // [s]
  const double arc_length_constant = kConstantGrowth * coarse.arc_length / (4.0 * h * h);
  const double forward_speed_constant = kConstantGrowth * coarse.forward_speed / (4.0 * h * h);
  EXPECT_LE(nominal.arc_length, arc_length_constant * h * h);
  EXPECT_LE(nominal.forward_speed, forward_speed_constant * h * h);
}

INSTANTIATE_TEST_SUITE_P(Paper, PaperCase,
                         ::testing::Values(Case{"birkhoff2", BirkhoffianForm::kPaper},
                                           Case{"birkhoff2", BirkhoffianForm::kAutonomous},
                                           Case{"rk2", BirkhoffianForm::kPaper}),
                         [](const ::testing::TestParamInfo<Case>& info) {
                           return info.param.integrator + "_" + to_string(info.param.form);
                         });

}  // namespace
}  // namespace birkhoff_cart
