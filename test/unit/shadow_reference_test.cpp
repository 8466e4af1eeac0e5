// The shadow-run reference (shadow_reference.h): one continuing dense-output dopri5 run, read at
// the compared instants; its work limits refused at load or failing with a StepError by name.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "birkhoff_cart/core/scene/scene.h"
#include "birkhoff_cart/core/run/shadow_reference.h"
#include "birkhoff_cart/core/run/simulation.h"

namespace birkhoff_cart {
namespace {

// Dense dopri5 at 1e-12 vs 10 fixed rk4 sub-steps of 0.1 ms (error ~1e-13 m over 2 s): they are two
// accurate solutions of the same problem [m].
constexpr double kShadowAgreement = 1e-8;

Scene load(const std::string& name) {
  return load_scene(std::string(BIRKHOFF_CART_SOURCE_DIR) + "/config/scenes/" + name + ".yaml");
}

/// The reference position error of `scene` after `steps` simulator steps, compared every
/// `compare_every` steps (0: only at the end).
double position_error_after(const Scene& scene, int steps, int compare_every) {
  Simulation simulation(scene);
  for (int k = 1; k <= steps; ++k) {
    simulation.step();
    if (compare_every > 0 && k % compare_every == 0) static_cast<void>(simulation.diagnostics());
  }
  return simulation.diagnostics().reference_position_error;
}

TEST(ShadowReference, DenseDopri5AgreesWithFineFixedStepShadow) {
  Scene dense = load("default");
  ASSERT_EQ(dense.reference.shadow.name, "dopri5");
  Scene fine = dense;
  fine.reference.shadow.name = "rk4";
  fine.reference.shadow.step_size = 1e-4;
  const double dense_error = position_error_after(dense, 2000, 10);
  const double fine_error = position_error_after(fine, 2000, 10);
  std::printf("birkhoff2 vs dense dopri5 shadow %.6e m, vs rk4 sub-steps %.6e m after 2 s\n", dense_error, fine_error);
  EXPECT_GT(dense_error, 0.0);
  EXPECT_NEAR(dense_error, fine_error, kShadowAgreement);
}

TEST(ShadowReference, ComparingMoreOftenDoesNotChangeTheShadow) {
  const Scene scene = load("default");
  const double every_step = position_error_after(scene, 1500, 1);
  const double every_tenth = position_error_after(scene, 1500, 10);
  const double only_at_end = position_error_after(scene, 1500, 0);
  EXPECT_EQ(every_step, only_at_end);
  EXPECT_EQ(every_tenth, only_at_end);
}

TEST(ShadowReference, CommandChangesTakeEffectAtTheSimulationsTime) {
  // driven.yaml takes commands; with a dopri5 shadow, a steering step at t = 0.5 s must be followed
  // by the shadow at the same instant: both runs then stay close (birkhoff2's own error).
  Scene scene = load("driven");
  scene.reference.kind = ReferenceSettings::Kind::kShadowRun;
  scene.reference.shadow.name = "dopri5";
  scene.reference.shadow.tolerance = 1e-12;
  scene.reference.shadow.step_size = 1e-3;
  Simulation simulation(scene);
  simulation.set_drive_command(20.0);
  for (int k = 1; k <= 2000; ++k) {
    if (k == 500) simulation.set_steering_command(3.0);
    if (k == 1200) simulation.set_steering_command(-2.0);
    simulation.step();
  }
  const double error = simulation.diagnostics().reference_position_error;
  std::printf("driven scene with command steps: birkhoff2 vs dopri5 shadow %.3e m after 2 s\n", error);
  // A shadow that missed a command change (held the old torque for even one step) is off by
  // ~Δτ h² / Θ ≈ 1e-6 m and more as the heading error grows.
  EXPECT_LT(error, 1e-6);
  EXPECT_GT(error, 0.0);
}

TEST(ShadowReference, TooTightToleranceIsRefusedAtLoadByName) {
  Scene scene = load("default");
  scene.reference.shadow.tolerance = 1e-25;
  try {
    Simulation simulation(scene);
    FAIL() << "a shadow tolerance of 1e-25 was accepted";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("reference.integrator.tolerance"), std::string::npos) << error.what();
  }
  scene.reference.shadow.tolerance = kShadowToleranceFloor;  // the floor itself is allowed
  EXPECT_NO_THROW(Simulation{scene});
}

TEST(ShadowReference, TinyFixedShadowStepIsRefusedAtLoadInsteadOfOverflowing) {
  // h / h_shadow = 1e-3 / 1e-300 overflowed lround: zero sub-steps and a meaningless reference.
  for (const double shadow_step : {1e-300, 1e-9}) {
    Scene scene = load("default");
    scene.reference.shadow.name = "rk4";
    scene.reference.shadow.step_size = shadow_step;
    try {
      Simulation simulation(scene);
      FAIL() << "a shadow step of " << shadow_step << " s was accepted";
    } catch (const std::invalid_argument& error) {
      EXPECT_NE(std::string(error.what()).find("reference.integrator.step_size"), std::string::npos)
          << error.what();
    }
  }
  Scene scene = load("default");
  scene.integrator.step_size = 1e-3;  // [s]
  scene.reference.shadow.name = "rk4";
  scene.reference.shadow.step_size = 1e-3 / kMaxShadowSubsteps;  // exactly at the limit
  EXPECT_NO_THROW(Simulation{scene});
}

TEST(ShadowReference, WorkLimitPerStepFailsWithANamedStepError) {
  // One "simulator step" of 1e6 s at the tightest tolerance needs far more than
  // kMaxShadowStepsPerStep dopri5 steps: a StepError naming the limit, not a hang.
  const Scene scene = load("default");
  Simulation simulation(scene);  // owns the model and effects the shadow integrates
  IntegratorSettings shadow = scene.reference.shadow;
  shadow.tolerance = kShadowToleranceFloor;
  const auto reference = make_shadow_reference(shadow, scene.integrator.step_size, scene.initial_state,
                                               simulation.model(), simulation.effects());
  try {
    reference->step(scene.initial_state.time + 1e6);
    FAIL() << "1e6 s in one step passed the work limit";
  } catch (const StepError& error) {
    EXPECT_NE(std::string(error.what()).find("work limit"), std::string::npos) << error.what();
  }
}

}  // namespace
}  // namespace birkhoff_cart
