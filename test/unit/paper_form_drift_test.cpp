// The paper's eᵗ form drifts (docs/birkhoffian.md §9): a member stepping in the chart
// w = (π1, χ, e^{t−tₑ} p) multiplies the momenta by 1 + δ per step whatever the motion, δ = h³/12 + …
// for birkhoff2. The core measures δ (paper_form_drift.h); these tests check the measured δ
// against the closed form, the predicted growth against a real run, and when the warning fires.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "birkhoff_cart/core/paper_form_drift.h"
#include "birkhoff_cart/core/scene.h"
#include "birkhoff_cart/core/simulation.h"

namespace birkhoff_cart {
namespace {

constexpr double kRoundOffDelta = 1e-14;       // |δ| of a member that does not drift [-]
constexpr double kClosedFormAgreement = 1e-6;  // relative, δ(birkhoff2) vs (1 + h/2)/(1 − h/2)·e^{−h} − 1 [-]
constexpr double kPredictionAgreement = 0.1;   // relative, predicted vs measured energy growth [-]

Scene scene(const std::string& integrator, BirkhoffianForm form, double step, double duration) {
  Scene s = load_scene(std::string(BIRKHOFF_CART_SOURCE_DIR) + "/config/scenes/free_coast.yaml");
  s.integrator.name = integrator;
  s.integrator.birkhoffian_form = form;
  s.integrator.step_size = step;
  s.duration = duration;
  return s;
}

TEST(PaperFormDrift, Birkhoff2StepMultipliesMomentaByTheClosedFormFactor) {
  for (double h : {0.01, 0.05, 0.1}) {
    const double delta = paper_form_momentum_change_per_step(scene("birkhoff2", BirkhoffianForm::kPaper, h, 1.0));
    const double closed_form = (1.0 + h / 2) / (1.0 - h / 2) * std::exp(-h) - 1.0;  // = h³/12 + O(h⁵)
    std::printf("[ measured ] birkhoff2 paper form h = %g: δ = %.6e per step (closed form %.6e, h³/12 = %.6e)\n", h,
                delta, closed_form, h * h * h / 12);
    EXPECT_NEAR(delta, closed_form, kClosedFormAgreement * closed_form) << "h = " << h;
  }
}

TEST(PaperFormDrift, AutonomousFormAndChartFreeMembersDoNotDrift) {
  for (const std::string& name : integrator_names()) {
    const double autonomous =
        paper_form_momentum_change_per_step(scene(name, BirkhoffianForm::kAutonomous, 0.05, 1.0));
    EXPECT_LE(std::abs(autonomous), kRoundOffDelta) << name;
    EXPECT_EQ(paper_form_drift_warning(scene(name, BirkhoffianForm::kAutonomous, 0.05, 1e5)), "") << name;
  }
  for (const char* name : {"midpoint", "rk4"}) {  // they integrate ż itself: the chart never enters
    const double paper = paper_form_momentum_change_per_step(scene(name, BirkhoffianForm::kPaper, 0.05, 1.0));
    EXPECT_LE(std::abs(paper), kRoundOffDelta) << name;
  }
  // birkhoff4's triple jump has Σγᵢ³ = 0: the h³ terms of its three substeps cancel, δ = O(h⁵).
  const double birkhoff4 = paper_form_momentum_change_per_step(scene("birkhoff4", BirkhoffianForm::kPaper, 0.05, 1.0));
  const double birkhoff2 = paper_form_momentum_change_per_step(scene("birkhoff2", BirkhoffianForm::kPaper, 0.05, 1.0));
  std::printf("[ measured ] paper form h = 0.05: δ(birkhoff2) = %.3e, δ(birkhoff4) = %.3e per step\n", birkhoff2,
              birkhoff4);
  EXPECT_LT(std::abs(birkhoff4), 1e-2 * birkhoff2);
}

TEST(PaperFormDrift, PredictedGrowthIsWhatARunShowsAndTheWarningFiresOnlyWhenItMatters) {
  // The free whirl in the paper form with birkhoff2 at h = 0.05 s over 100 s: the energy, ∝ p²,
  // grows by (1 + g)² − 1 with g the predicted momentum growth; the autonomous run stays put.
  constexpr double kStep = 0.05, kDuration = 100.0;  // [s]
  const Scene paper = scene("birkhoff2", BirkhoffianForm::kPaper, kStep, kDuration);
  const double growth = paper_form_momentum_growth(paper, kDuration);
  const double predicted_energy_growth = (1.0 + growth) * (1.0 + growth) - 1.0;
  Simulation drifting(paper);
  Simulation steady(scene("birkhoff2", BirkhoffianForm::kAutonomous, kStep, kDuration));
  const double energy0 = drifting.diagnostics().energy;
  drifting.advance_to(drifting.end_time());
  steady.advance_to(steady.end_time());
  const double measured = drifting.diagnostics().energy / energy0 - 1.0;
  const double autonomous = steady.diagnostics().energy / energy0 - 1.0;
  std::printf("[ measured ] free whirl 100 s, h = 0.05 s: paper-form energy %+.4e (predicted %+.4e), autonomous %+.3e\n",
              measured, predicted_energy_growth, autonomous);
  EXPECT_NEAR(measured, predicted_energy_growth, kPredictionAgreement * predicted_energy_growth);
  EXPECT_LT(std::abs(autonomous), 1e-2 * predicted_energy_growth);
  // The warning: on for this run, off for a run too short to drift by 0.1 %.
  const std::string warning = paper_form_drift_warning(paper);
  EXPECT_NE(warning.find("birkhoff2"), std::string::npos) << warning;
  EXPECT_NE(warning.find("autonomous"), std::string::npos) << warning;
  EXPECT_EQ(paper_form_drift_warning(scene("birkhoff2", BirkhoffianForm::kPaper, kStep, 1.0)), "");
  EXPECT_EQ(paper_form_drift_warning(scene("midpoint", BirkhoffianForm::kPaper, kStep, 1e4)), "");
}

}  // namespace
}  // namespace birkhoff_cart
