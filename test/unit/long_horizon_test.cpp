// A one-hour simulated run (3.6e6 steps of 1 ms) of the driven default scene (drive torque ramp,
// rolling resistance, air drag, cosine steering torque, hinge damping) with birkhoff2 in both
// Birkhoffian representations (docs/hard_cases.md §7). The paper's form carries
// K = e^{t}J: e^{3600} overflows a double (checked below), so the run only stays finite because the
// structure epoch tₑ is moved to every step's start (cart_birkhoffian.h). Checked: every state
// finite, the run reaches t = 3600 s exactly, the energy and p2 balances (docs eqs. (3.7), (3.8))
// and the constraints hold at every simulated second, and the two representations agree.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>

#include "birkhoff_cart/core/physics/cart_birkhoffian.h"
#include "birkhoff_cart/core/scene/scene.h"
#include "birkhoff_cart/core/run/simulation.h"
#include "generated_docs.h"

namespace birkhoff_cart {
namespace {

constexpr double kOneHour = 3600.0;  // [s]
constexpr std::uint64_t kStepsPerSecond = 1000;  // h = 1 ms
// |T* − T*₀ − W| at every second [J], T* ≈ 780 J cruising: the autonomous form keeps the balance
// (measured max 1.3e-5 J over the hour); the paper form's chart w = e^{t−tₑ}p is re-anchored every
// step, and its O(h²) balance error accumulates (measured max 0.56 J = 7e-4 T*; docs/hard_cases.md §7).
constexpr double kEnergyBalanceToleranceAutonomous = 1e-3;
constexpr double kEnergyBalanceTolerancePaper = 2.0;
// |p2 − p2₀ − ∫Q2 dt| [kg·m²/s] (measured max 4.4e-13 autonomous, 4.0e-7 paper form).
constexpr double kSteeringMomentumBalanceTolerance = 1e-5;
// max |eq. (15) residual| [m/s].
constexpr double kConstraintTolerance = 1e-9;
// The two representations are the same ODE integrated in different charts: after an hour of a
// dissipative, forced (hence contracting) run their speeds agree to [m/s] (measured 2.2e-5).
constexpr double kFormAgreementSpeed = 1e-3;

struct HourOutcome {
  bool finite = true;
  CartState last;
  double max_energy_balance = 0.0;       ///< [J]
  double max_p2_balance = 0.0;           ///< [kg·m²/s]
  double max_constraint = 0.0;           ///< [m/s]
  double seconds = 0.0;                  ///< wall time [s]
};

HourOutcome run_one_hour(BirkhoffianForm form) {
  Scene scene = load_scene(std::string(BIRKHOFF_CART_SOURCE_DIR) + "/config/scenes/default.yaml");
  scene.reference.kind = ReferenceSettings::Kind::kNone;  // no dopri5 shadow for an hour
  scene.integrator.name = "birkhoff2";
  scene.integrator.step_size = 1.0 / static_cast<double>(kStepsPerSecond);
  scene.integrator.birkhoffian_form = form;
  scene.duration = kOneHour;
  Simulation simulation(scene);
  HourOutcome outcome;
  const auto start = std::chrono::steady_clock::now();
  for (std::uint64_t second = 0; second < static_cast<std::uint64_t>(kOneHour); ++second) {
    for (std::uint64_t k = 0; k < kStepsPerSecond; ++k) simulation.step();
    const CartState& state = simulation.state();
    outcome.finite = outcome.finite && std::isfinite(state.x) && std::isfinite(state.y) &&
                     std::isfinite(state.heading) && std::isfinite(state.steering_angle) &&
                     std::isfinite(state.arc_length) && std::isfinite(state.forward_speed) &&
                     std::isfinite(state.steering_rate) && std::isfinite(state.applied_work) &&
                     std::isfinite(state.steering_impulse);
    const Diagnostics diagnostics = simulation.diagnostics();
    outcome.max_energy_balance = std::max(outcome.max_energy_balance, std::abs(diagnostics.energy_balance_residual));
    outcome.max_p2_balance = std::max(outcome.max_p2_balance, std::abs(diagnostics.p2_balance_residual));
    outcome.max_constraint = std::max(outcome.max_constraint, diagnostics.max_constraint_residual);
    if (!outcome.finite) break;
  }
  outcome.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  outcome.last = simulation.state();
  std::printf("[ measured ] one hour, birkhoff2 %s form: %.1f s wall, t = %.3f s, omega1 = %.6f m/s, T* - T*0 - W max "
              "%.3g J, p2 balance max %.3g kg m^2/s, constraints %.3g m/s, pi1 = %.1f m\n",
              to_string(form), outcome.seconds, outcome.last.time, outcome.last.forward_speed, outcome.max_energy_balance,
              outcome.max_p2_balance, outcome.max_constraint, outcome.last.arc_length);
  return outcome;
}

TEST(LongHorizon, TheStructureFactorWouldOverflowWithoutTheEpoch) {
  EXPECT_TRUE(std::isinf(std::exp(kOneHour)));  // e^{t} at t = 1 h: why tₑ is needed
  const Scene scene = load_scene(std::string(BIRKHOFF_CART_SOURCE_DIR) + "/config/scenes/default.yaml");
  const CartModel model(scene.cart);
  const EffectSet effects;
  CartPaperBirkhoffian system(model, effects);
  system.begin_step(kOneHour);
  const double factor = system.conformal_factor(kOneHour + 1e-3);  // e^{t − tₑ} one step later
  EXPECT_TRUE(std::isfinite(factor));
  EXPECT_EQ(factor, std::exp((kOneHour + 1e-3) - kOneHour));  // e^{h} with h as the double grid has it
}

TEST(LongHorizon, OneDrivenHourInBothRepresentationsKeepsItsBalances) {
  const HourOutcome autonomous = run_one_hour(BirkhoffianForm::kAutonomous);
  const HourOutcome paper = run_one_hour(BirkhoffianForm::kPaper);
  for (const HourOutcome* outcome : {&autonomous, &paper}) {
    const char* form = to_string(outcome == &autonomous ? BirkhoffianForm::kAutonomous : BirkhoffianForm::kPaper);
    ASSERT_TRUE(outcome->finite) << form << " stopped being finite at t = " << outcome->last.time;
    EXPECT_EQ(outcome->last.time, kOneHour) << form;  // t₀ + n h exactly
    EXPECT_LT(outcome->max_energy_balance,
              outcome == &autonomous ? kEnergyBalanceToleranceAutonomous : kEnergyBalanceTolerancePaper)
        << form;
    EXPECT_LT(outcome->max_p2_balance, kSteeringMomentumBalanceTolerance) << form;
    EXPECT_LT(outcome->max_constraint, kConstraintTolerance) << form;
    EXPECT_GT(outcome->last.forward_speed, 1.0) << form << ": the driven cart should still be cruising";
  }
  EXPECT_NEAR(autonomous.last.forward_speed, paper.last.forward_speed, kFormAgreementSpeed);
  // docs/hard_cases.md §7 quotes these runs (wall time aside): two-digit figures within 6 %, round-off
  // as the bound it states, ω1 to the six decimals shown.
  const std::string page = "docs/hard_cases.md";
  for (const HourOutcome* outcome : {&autonomous, &paper}) {
    const std::string row = std::string("| ") + (outcome == &autonomous ? "autonomous" : "paper") + " | ";
    const std::vector<double> stated = birkhoff_cart_test::figures_after(page, row);
    ASSERT_EQ(stated.size(), 4u) << page << " §7: the row '" << row << "' should state 4 figures";
    const std::string form = row + "...";
    EXPECT_TRUE(birkhoff_cart_test::page_figure_agrees(page, row, 0, outcome->max_energy_balance, 0.06)) << form;
    if (outcome == &autonomous) {
      EXPECT_LE(outcome->max_p2_balance, stated[1]) << form;
    } else {
      EXPECT_TRUE(birkhoff_cart_test::page_figure_agrees(page, row, 1, outcome->max_p2_balance, 0.06)) << form;
    }
    EXPECT_LE(outcome->max_constraint, stated[2]) << form;
    EXPECT_NEAR(outcome->last.forward_speed, stated[3], 5e-7) << form;
  }
}

}  // namespace
}  // namespace birkhoff_cart
