// The registry's table (integrator_registry.h) against the steppers its factories build, member by
// member, so a new row is checked without touching this file:
//  - the name, order and symmetry each built stepper reports are the row's, at fixed steps and
//    under the reversible step control; the order is also measured, by step halving on the forced
//    cart (the symmetry by reversal: registry_properties_test);
//  - a row that claims the reversible control builds it and meets a position tolerance with it; any
//    other is refused by name; the claim is the rule "symmetric Birkhoffian member";
//  - a row that claims the adaptive control builds it and meets a position tolerance with it on a
//    forced scene; any other is refused by name (with the row's reason where it has one); the claim is the rule
//    "Birkhoffian member or dopri5, unless its row refuses it";
//  - a row that claims a tolerance (kind adaptive) refuses one below its floor; the others ignore it;
//  - cart_simulate --help shows each row's order, symmetry, reversible and adaptive control;
// and the names: every member, form and control parses and round-trips through its text, and an
// unknown one is refused by name with the known list and the closest name.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "birkhoff_cart/core/physics/cart_model.h"
#include "birkhoff_cart/core/physics/effect_library.h"
#include "birkhoff_cart/core/cart_binding/cart_stepper.h"
#include "birkhoff_cart/core/cart_binding/integrator_registry.h"
#include "birkhoff_cart/core/integrators/adaptive_refusal.h"
#include "birkhoff_cart/core/scene/scene.h"
#include "birkhoff_cart/core/run/simulation.h"
#include "birkhoff_cart/core/integrators/vector_math.h"
#include "test_scenes.h"

namespace birkhoff_cart {
namespace {

constexpr double kOrderSlack = 0.3;            // |observed − claimed order| up to order 4 [-]
constexpr double kHighOrderExcess = 2.0;       // orders ≥ 5 may show up to this much more (see expect_order) [-]
constexpr double kReferenceTolerance = 1e-13;  // dopri5's tolerance for the forced cart's reference [-]
constexpr double kMemberTolerance = 1e-8;        // an adaptive member's own tolerance (dopri5) [-]
constexpr double kForcedCartDuration = 1.0;    // [s]
constexpr double kPositionTolerance = 1e-5;    // the reversible runs' position tolerance [m]
constexpr double kWhirlDuration = 2.0;         // the reversible runs' duration [s]
constexpr double kBelowEveryFloor = 1e-300;    // a local tolerance no adaptive member accepts [-]
constexpr double kForcedSceneDuration = 3.0;   // the adaptive runs' stretch of drive_rr_drag [s]

Scene load(const std::string& name) { return load_scene(birkhoff_cart_test::scene_path(name)); }

/// `scene` from its start with n steps of kForcedCartDuration / n, through the registry.
CartState run_steps(const Scene& scene, const IntegratorSettings& settings, int steps) {
  const CartModel model(scene.cart);
  const EffectSet effects = build_effects(scene.effects, model);
  const std::unique_ptr<CartStepper> stepper = make_cart_stepper(settings, model, effects);
  const double h = kForcedCartDuration / steps;
  CartState state = scene.initial_state;
  StepStatistics statistics;
  for (int k = 1; k <= steps; ++k) {
    stepper->step(state, h, statistics);
    state.time = scene.initial_state.time + k * h;
  }
  return state;
}

/// The settings a row's order is measured with: dopri5 at full steps (its controller accepts each).
IntegratorSettings fixed_settings(const IntegratorEntry& member) {
  IntegratorSettings settings;
  settings.name = member.name;
  if (member.takes_tolerance()) settings.tolerance = kMemberTolerance;
  return settings;
}

/// Coarsest step count over the forced cart's second for order p (then ×2, ×4): errors in the
/// asymptotic range and above the reference's at every level.
int coarsest_steps(int order) { return order <= 2 ? 100 : order <= 4 ? 20 : order <= 6 ? 8 : 3; }

/// Up to order 4 the observed order is the claimed one within kOrderSlack; from order 5 on, the
/// forced cart's error still falls faster than h^p over the steps that stay above the reference
/// (measured: dopri5 6.2–6.4, the order-8 members 7.9–8.2): p − kOrderSlack ≤ observed ≤ p + 2.
void expect_order(double observed, int claimed, const std::string& what) {
  if (claimed <= 4) {
    EXPECT_NEAR(observed, claimed, kOrderSlack) << what;
  } else {
    EXPECT_GE(observed, claimed - kOrderSlack) << what;
    EXPECT_LE(observed, claimed + kHighOrderExcess) << what;
  }
}

/// The jackknife whirl under the reversible control with `name`, output step 0.5 s.
Scene reversible_whirl(const std::string& name) {
  Scene scene = load("jackknife_whirl");
  scene.reference = ReferenceSettings{};
  scene.duration = kWhirlDuration;
  scene.integrator.name = name;
  scene.integrator.step_size = 0.5;
  scene.integrator.step_control = StepControl::kReversible;
  scene.integrator.position_tolerance = kPositionTolerance;
  return scene;
}

CartState run_to_end(const Scene& scene) {
  Simulation simulation(scene);
  while (!simulation.at_end()) simulation.step_on_schedule();
  return simulation.state();
}

std::vector<IntegratorEntry> members() { return integrator_registry(); }

class RegistryRow : public testing::TestWithParam<IntegratorEntry> {};

TEST_P(RegistryRow, TheBuiltStepperHasTheRowsNameOrderAndSymmetry) {
  const IntegratorEntry& member = GetParam();
  const CartModel model{CartParameters{}};
  const EffectSet effects;
  for (BirkhoffianForm form : {BirkhoffianForm::kAutonomous, BirkhoffianForm::kPaper}) {
    IntegratorSettings settings = fixed_settings(member);
    settings.birkhoffian_form = form;
    const std::unique_ptr<CartStepper> stepper = make_cart_stepper(settings, model, effects);
    EXPECT_EQ(stepper->name(), member.name) << to_string(form);
    EXPECT_EQ(stepper->order(), member.order) << member.name << " " << to_string(form);
    EXPECT_EQ(stepper->symmetric(), member.symmetric) << member.name << " " << to_string(form);
  }
}

TEST_P(RegistryRow, TheMeasuredOrderIsTheRowsOrder) {
  // sine_steer_torque (χ₀ = 0, ω1 = 5 m/s, τ = 3 cos(π t) N·m) over 1 s against dopri5 at 1e-13.
  const IntegratorEntry& member = GetParam();
  if (member.takes_tolerance()) {
    // dopri5 runs its own steps over the whole run (dopri5_cart_stepper.h): the caller's step does
    // not set its error, and its order is measured on its stepper (integrator_contract_test).
    std::printf("[ measured ] %s: its own steps, order checked by integrator_contract_test\n", member.name);
    return;
  }
  const Scene scene = load("sine_steer_torque");
  IntegratorSettings reference_settings;
  reference_settings.name = "dopri5";
  reference_settings.tolerance = kReferenceTolerance;
  const CartState reference = run_steps(scene, reference_settings, 100);
  double errors[3];
  for (int level = 0; level < 3; ++level) {
    const CartState end = run_steps(scene, fixed_settings(member), coarsest_steps(member.order) << level);
    errors[level] = std::hypot(end.x - reference.x, end.y - reference.y);  // the hinge's position error [m]
  }
  const double order12 = std::log2(errors[0] / errors[1]), order23 = std::log2(errors[1] / errors[2]);
  std::printf("[ measured ] %s (order %d): errors %.3e %.3e %.3e, observed orders %.3f %.3f\n", member.name,
              member.order, errors[0], errors[1], errors[2], order12, order23);
  expect_order(order12, member.order, member.name);
  expect_order(order23, member.order, member.name);
}

TEST_P(RegistryRow, TheReversibleControlIsBuiltExactlyWhereTheRowOffersIt) {
  const IntegratorEntry& member = GetParam();
  // The rule the refusal states: the reversible control is for the symmetric Birkhoffian members.
  const bool birkhoffian =
      member.kind == IntegratorKind::kBirkhoffianCollocation || member.kind == IntegratorKind::kComposition;
  EXPECT_EQ(member.reversible(), member.symmetric && birkhoffian) << member.name;
  const Scene scene = reversible_whirl(member.name);
  if (!member.reversible()) {
    try {
      Simulation refused(scene);
      FAIL() << member.name << " was built under the reversible step control";
    } catch (const std::invalid_argument& error) {
      const std::string message = error.what();
      EXPECT_NE(message.find("'" + std::string(member.name) + "'"), std::string::npos) << message;
      for (const std::string& name : reversible_integrator_names()) {
        EXPECT_NE(message.find(name), std::string::npos) << message;
      }
    }
    return;
  }
  Simulation simulation(scene);
  const CartModel model(scene.cart);
  const EffectSet effects;
  IntegratorSettings settings = scene.integrator;
  settings.tolerance_horizon = kWhirlDuration;
  const std::unique_ptr<CartStepper> stepper = make_cart_stepper(settings, model, effects);
  EXPECT_EQ(stepper->name(), member.name);
  EXPECT_EQ(stepper->order(), member.order) << member.name;
  EXPECT_TRUE(stepper->symmetric()) << member.name;
  // It meets the tolerance: the end against birkhoff_gauss8 at fixed steps of 2 ms.
  Scene reference_scene = load("jackknife_whirl");
  reference_scene.reference = ReferenceSettings{};
  reference_scene.duration = kWhirlDuration;
  reference_scene.integrator.name = "birkhoff_gauss8";
  reference_scene.integrator.step_size = 2e-3;
  const CartState reference = run_to_end(reference_scene);
  while (!simulation.at_end()) simulation.step_on_schedule();
  const double error = std::hypot(simulation.state().x - reference.x, simulation.state().y - reference.y);
  std::printf("[ measured ] %s reversible at %.0e m over %.0f s: position error %.3e m in %llu internal steps\n",
              member.name, kPositionTolerance, kWhirlDuration, error,
              static_cast<unsigned long long>(simulation.statistics().internal_steps));
  EXPECT_LT(error, 10.0 * kPositionTolerance) << member.name;
  EXPECT_GT(simulation.statistics().internal_steps, 0u) << member.name;
}

TEST_P(RegistryRow, TheAdaptiveControlIsBuiltExactlyWhereTheRowOffersIt) {
  const IntegratorEntry& member = GetParam();
  // The rule the refusal states: the Birkhoffian members (their error estimate drives it) and dopri5,
  // but for those whose row gives the reason their estimate cannot steer it.
  const bool birkhoffian =
      member.kind == IntegratorKind::kBirkhoffianCollocation || member.kind == IntegratorKind::kComposition;
  EXPECT_EQ(member.adaptive(),
            (birkhoffian || member.kind == IntegratorKind::kAdaptive) && adaptive_refusal(member.name) == nullptr)
      << member.name;
  // A forced, dissipative stretch: the drive's start-up transient of drive_rr_drag.
  Scene scene = load("drive_rr_drag");
  scene.reference = ReferenceSettings{};
  scene.duration = kForcedSceneDuration;
  scene.integrator.name = member.name;
  scene.integrator.step_control = StepControl::kAdaptive;
  scene.integrator.position_tolerance = kPositionTolerance;
  scene.integrator.tolerance_horizon = kForcedSceneDuration;
  scene.integrator.step_size = kForcedSceneDuration;
  if (!member.adaptive()) {
    try {
      Simulation refused(scene);
      FAIL() << member.name << " was built under the adaptive step control";
    } catch (const std::invalid_argument& error) {
      const std::string message = error.what();
      EXPECT_NE(message.find("'" + std::string(member.name) + "'"), std::string::npos) << message;
      for (const std::string& name : adaptive_integrator_names()) {
        EXPECT_NE(message.find(name), std::string::npos) << message;
      }
      if (const char* reason = adaptive_refusal(member.name)) {
        EXPECT_NE(message.find(reason), std::string::npos) << message;
      }
    }
    return;
  }
  Simulation simulation(scene);
  EXPECT_TRUE(simulation.takes_own_steps()) << member.name;
  simulation.advance_output_to(simulation.end_time());
  Scene reference_scene = scene;
  reference_scene.integrator = IntegratorSettings{};
  reference_scene.integrator.name = "birkhoff_gauss8";
  reference_scene.integrator.step_size = 1e-3;
  const CartState reference = run_to_end(reference_scene);
  const double error = std::hypot(simulation.state().x - reference.x, simulation.state().y - reference.y);
  std::printf("[ measured ] %s adaptive at %.0e m over %.0f s of drive_rr_drag: position error %.3e m in %llu internal "
              "steps, %llu rejected\n",
              member.name, kPositionTolerance, kForcedSceneDuration, error,
              static_cast<unsigned long long>(simulation.statistics().internal_steps),
              static_cast<unsigned long long>(simulation.statistics().rejected_steps));
  EXPECT_LT(error, 10.0 * kPositionTolerance) << member.name;
  EXPECT_GT(simulation.statistics().internal_steps, 0u) << member.name;
}

TEST_P(RegistryRow, OnlyARowThatTakesAToleranceReadsIt) {
  const IntegratorEntry& member = GetParam();
  const CartModel model{CartParameters{}};
  const EffectSet effects;
  IntegratorSettings settings;
  settings.name = member.name;
  settings.tolerance = kBelowEveryFloor;
  if (member.takes_tolerance()) {
    EXPECT_THROW(make_cart_stepper(settings, model, effects), std::invalid_argument) << member.name;
  } else {
    EXPECT_NO_THROW(make_cart_stepper(settings, model, effects)) << member.name;
  }
}

TEST_P(RegistryRow, HelpShowsTheRowsOrderSymmetryAndStepControls) {
  const IntegratorEntry& member = GetParam();
  const std::string help =
      birkhoff_cart_test::standard_output_of("'" + birkhoff_cart_test::cart_simulate_path() + "' --help");
  const std::string start = "\n  " + std::string(member.name) + " ";
  const auto at = help.find(start);
  ASSERT_NE(at, std::string::npos) << member.name << " has no row in cart_simulate --help:\n" << help;
  std::istringstream row(help.substr(at + 1, help.find('\n', at + 1) - at - 1));
  std::string name, symmetric, reversible, adaptive;
  int order = 0;
  row >> name >> order >> symmetric >> reversible >> adaptive;
  EXPECT_EQ(name, member.name);
  EXPECT_EQ(order, member.order) << member.name;
  EXPECT_EQ(symmetric, member.symmetric ? "yes" : "no") << member.name;
  EXPECT_EQ(reversible, member.reversible() ? "yes" : "no") << member.name;
  EXPECT_EQ(adaptive, member.adaptive() ? "yes" : "no") << member.name;
  EXPECT_NE(help.find(member.description, at), std::string::npos) << member.name;
  EXPECT_NE(help.find(to_string(member.kind), at), std::string::npos) << member.name;
}

TEST_P(RegistryRow, VectorStagesIsWhereTheStagesAreEvaluatedTogether) {
  const IntegratorEntry& member = GetParam();
  // The claim: the Gauss members from two stages on evaluate their stages together.
  EXPECT_EQ(member.vector_stages, member.kind == IntegratorKind::kBirkhoffianCollocation && member.order >= 4)
      << member.name;
  // Checked on the stepper: it calls the stage batch (sin_cos_lanes) exactly when the row says so.
  const std::uint64_t before = sin_cos_lanes_calls();
  run_steps(load("sine_steer_torque"), fixed_settings(member), 20);
  EXPECT_EQ(sin_cos_lanes_calls() > before, member.vector_stages) << member.name;
}

INSTANTIATE_TEST_SUITE_P(EveryMember, RegistryRow, testing::ValuesIn(members()),
                         [](const testing::TestParamInfo<IntegratorEntry>& info) { return info.param.name; });

TEST(IntegratorNames, AreTheTablesAndEachFindsItsRow) {
  const std::vector<std::string> names = integrator_names();
  ASSERT_EQ(names.size(), integrator_registry().size());
  EXPECT_EQ(std::set<std::string>(names.begin(), names.end()).size(), names.size()) << "a name appears twice";
  std::vector<std::string> reversible, adaptive;
  for (std::size_t i = 0; i < names.size(); ++i) {
    const IntegratorEntry& member = integrator_registry()[i];
    EXPECT_EQ(names[i], member.name);
    ASSERT_EQ(find_integrator(names[i]), &member) << names[i];
    EXPECT_EQ(&integrator_entry(names[i]), &member) << names[i];
    EXPECT_FALSE(std::string(member.description).empty()) << names[i];
    if (member.reversible()) reversible.push_back(member.name);
    if (member.adaptive()) adaptive.push_back(member.name);
  }
  EXPECT_EQ(reversible_integrator_names(), reversible);
  EXPECT_EQ(adaptive_integrator_names(), adaptive);
}

TEST(IntegratorNames, AnUnknownNameIsRefusedByNameWithTheKnownOnesAndTheClosest) {
  for (const std::string unknown : {"", "RK4", "rk4 ", "euler"}) EXPECT_EQ(find_integrator(unknown), nullptr) << unknown;
  try {
    integrator_entry("birkhof2");
    FAIL() << "an unknown integrator was found";
  } catch (const std::invalid_argument& error) {
    const std::string message = error.what();
    EXPECT_EQ(message.find("unknown integrator 'birkhof2' (known: "), 0u) << message;
    for (const std::string& name : integrator_names()) EXPECT_NE(message.find(name), std::string::npos) << message;
    EXPECT_NE(message.find("did you mean 'birkhoff2'?"), std::string::npos) << message;
  }
  try {  // the same refusal through make_cart_stepper, and no guess for an unrelated word
    IntegratorSettings settings;
    settings.name = "euler";
    make_cart_stepper(settings, CartModel{CartParameters{}}, EffectSet{});
    FAIL() << "euler was built";
  } catch (const std::invalid_argument& error) {
    const std::string message = error.what();
    EXPECT_EQ(message.find("unknown integrator 'euler' (known: "), 0u) << message;
    EXPECT_EQ(message.find("did you mean"), std::string::npos) << message;
  }
}

TEST(IntegratorKinds, EachHasItsOwnText) {
  std::set<std::string> texts;
  for (IntegratorKind kind : {IntegratorKind::kBirkhoffianCollocation, IntegratorKind::kComposition,
                              IntegratorKind::kExplicitRungeKutta, IntegratorKind::kAdaptive,
                              IntegratorKind::kImplicitMidpoint}) {
    texts.insert(to_string(kind));
  }
  EXPECT_EQ(texts.size(), 5u);
  EXPECT_EQ(texts.count(""), 0u);
}

TEST(BirkhoffianForms, EveryTextParsesAndRoundTrips) {
  EXPECT_EQ(birkhoffian_form_names(), (std::vector<std::string>{"autonomous", "paper"}));
  for (const std::string& text : birkhoffian_form_names()) EXPECT_EQ(to_string(parse_birkhoffian_form(text)), text);
  for (BirkhoffianForm form : {BirkhoffianForm::kAutonomous, BirkhoffianForm::kPaper}) {
    EXPECT_EQ(parse_birkhoffian_form(to_string(form)), form);
  }
}

TEST(StepControls, EveryTextParsesAndRoundTrips) {
  EXPECT_EQ(step_control_names(), (std::vector<std::string>{"fixed", "reversible", "adaptive"}));
  for (const std::string& text : step_control_names()) EXPECT_EQ(to_string(parse_step_control(text)), text);
  for (StepControl control : {StepControl::kFixed, StepControl::kReversible, StepControl::kAdaptive}) {
    EXPECT_EQ(parse_step_control(to_string(control)), control);
  }
}

/// The message of `parse(text)`'s refusal; "" if it parsed.
template <class Parse>
std::string refusal(Parse parse, const std::string& text) {
  try {
    parse(text);
  } catch (const std::invalid_argument& error) {
    return error.what();
  }
  return "";
}

TEST(BirkhoffianForms, AnUnknownFormIsRefusedByNameWithTheKnownOnesAndTheClosest) {
  EXPECT_EQ(refusal(parse_birkhoffian_form, "autonomus"),
            "unknown birkhoffian_form 'autonomus' (known: autonomous, paper; did you mean 'autonomous'?)");
  EXPECT_EQ(refusal(parse_birkhoffian_form, "hamiltonian"),
            "unknown birkhoffian_form 'hamiltonian' (known: autonomous, paper)");
  EXPECT_NE(refusal(parse_birkhoffian_form, "Paper"), "");
  EXPECT_NE(refusal(parse_birkhoffian_form, ""), "");
}

TEST(StepControls, AnUnknownControlIsRefusedByNameWithTheKnownOnesAndTheClosest) {
  EXPECT_EQ(refusal(parse_step_control, "reversable"),
            "unknown step_control 'reversable' (known: fixed, reversible, adaptive; did you mean 'reversible'?)");
  EXPECT_EQ(refusal(parse_step_control, "variable"),
            "unknown step_control 'variable' (known: fixed, reversible, adaptive)");
  EXPECT_NE(refusal(parse_step_control, "FIXED"), "");
  EXPECT_NE(refusal(parse_step_control, ""), "");
}

}  // namespace
}  // namespace birkhoff_cart
