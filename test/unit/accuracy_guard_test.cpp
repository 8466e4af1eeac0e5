// AccuracyGuard (accuracy_guard.h, docs/accuracy.md §2): levels on made-up diagnostics, the scene's
// `accuracy` keys, the made-up bad run it must catch (a short-wheelbase whirl with rk4 at the
// scene's step, which ends with a 92 % energy error), no alarm on any shipped scene, and the
// batch CLI's exit status and summary.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <string>
#include <vector>

#include "birkhoff_cart/core/scene/accuracy_guard.h"
#include "birkhoff_cart/core/scene/scene.h"
#include "birkhoff_cart/core/run/simulation.h"
#include "generated_docs.h"
#include "test_scenes.h"

namespace birkhoff_cart {
namespace {

using birkhoff_cart_test::read_file;
using birkhoff_cart_test::replaced_once;
using birkhoff_cart_test::scene_path;

std::string temp_path(const std::string& name) {
  return ::testing::TempDir() + "accuracy_guard_test_" + std::to_string(getpid()) + "_" + name;
}

/// Diagnostics of a state with energy T* [J] and energy balance residual [J].
Diagnostics made_up(double energy, double energy_residual, double p2_residual = 0.0, double constraint = 0.0) {
  Diagnostics diagnostics;
  diagnostics.energy = energy;
  diagnostics.energy_balance_residual = energy_residual;
  diagnostics.p2_balance_residual = p2_residual;
  diagnostics.max_constraint_residual = constraint;
  return diagnostics;
}

TEST(AccuracyGuard, GoesWarnThenErrorNamingTheQuantityAndWhen) {
  AccuracyGuard guard;  // defaults: energy_balance_relative warn 1e-4, error 1e-2
  const StepStatistics statistics;
  EXPECT_EQ(guard.check(0.0, made_up(100.0, 0.0), statistics), AccuracyLevel::kOk);
  EXPECT_EQ(guard.check(1.0, made_up(100.0, 0.005), statistics), AccuracyLevel::kOk);  // 5e-5
  EXPECT_EQ(guard.check(2.0, made_up(100.0, 0.05), statistics), AccuracyLevel::kWarn);  // 5e-4
  EXPECT_EQ(guard.level(), AccuracyLevel::kWarn);
  EXPECT_EQ(guard.check(3.0, made_up(100.0, -2.0), statistics), AccuracyLevel::kError);  // 2e-2
  EXPECT_EQ(guard.check(4.0, made_up(100.0, 0.0), statistics), AccuracyLevel::kOk);  // current level recovers
  EXPECT_EQ(guard.level(), AccuracyLevel::kError);                                     // the worst stays
  ASSERT_EQ(guard.events().size(), 2u);
  EXPECT_EQ(guard.events()[0].level, AccuracyLevel::kWarn);
  EXPECT_EQ(guard.events()[0].time, 2.0);
  EXPECT_EQ(guard.events()[1].level, AccuracyLevel::kError);
  EXPECT_EQ(guard.events()[1].quantity, AccuracyQuantity::kEnergyBalanceRelative);
  EXPECT_EQ(guard.events()[1].time, 3.0);
  EXPECT_DOUBLE_EQ(guard.events()[1].value, 0.02);
  EXPECT_EQ(guard.largest_value(AccuracyQuantity::kEnergyBalanceRelative), 0.02);
  const std::string summary = guard.summary();
  EXPECT_EQ(summary.rfind("ERROR:", 0), 0u) << summary;
  EXPECT_NE(summary.find("energy_balance_relative 0.02 > 0.01"), std::string::npos) << summary;
  EXPECT_NE(summary.find("t = 3 s"), std::string::npos) << summary;
  guard.reset();
  EXPECT_EQ(guard.level(), AccuracyLevel::kOk);
  EXPECT_TRUE(guard.events().empty());
  EXPECT_EQ(guard.summary(), "OK");
}

TEST(AccuracyGuard, EnergyScaleIsTheLargestEnergySeenAndZeroOverZeroIsNoError) {
  AccuracyGuard guard;
  const StepStatistics statistics;
  EXPECT_EQ(guard.check(0.0, made_up(0.0, 0.0), statistics), AccuracyLevel::kOk);  // a cart at rest
  EXPECT_EQ(guard.check(1.0, made_up(0.0, 1e-30), statistics), AccuracyLevel::kError);  // r / 0
  AccuracyGuard driven;
  driven.check(0.0, made_up(1000.0, 0.0), statistics);  // T* fell from 1000 J to 10 J: scale stays 1000 J
  EXPECT_EQ(driven.check(1.0, made_up(10.0, 0.05), statistics), AccuracyLevel::kOk);  // 5e-5 of 1000 J
  EXPECT_DOUBLE_EQ(driven.current_value(AccuracyQuantity::kEnergyBalanceRelative), 5e-5);
}

TEST(AccuracyGuard, AbsoluteEnergyBalanceIsJudgedInJoulesAndOffByDefault) {
  const StepStatistics statistics;
  AccuracyGuard defaults;  // off: a 1 J residual on 1e6 J (1e-6) is fine for the relative limit
  EXPECT_EQ(defaults.check(0.0, made_up(1e6, 1.0), statistics), AccuracyLevel::kOk);
  EXPECT_EQ(defaults.current_value(AccuracyQuantity::kEnergyBalance), 1.0);
  AccuracyRequirements requirements;
  requirements.energy_balance = {true, 1e-4, 1e-1};  // [J]
  AccuracyGuard guard(requirements);
  EXPECT_EQ(guard.check(0.0, made_up(1e6, -1e-3), statistics), AccuracyLevel::kWarn);
  EXPECT_EQ(guard.events().back().quantity, AccuracyQuantity::kEnergyBalance);
  EXPECT_EQ(guard.check(1.0, made_up(1e6, 1.0), statistics), AccuracyLevel::kError);
  const std::string summary = guard.summary();
  EXPECT_NE(summary.find("energy_balance 1 > 0.1 J"), std::string::npos) << summary;
  EXPECT_EQ(summary.find("energy_balance_relative"), std::string::npos) << summary;  // 1e-6 of T*: fine
  requirements.energy_balance = {true, 1.0, 0.5};
  EXPECT_THROW(AccuracyGuard{requirements}, std::invalid_argument);
}

TEST(AccuracyGuard, NewRequirementsJudgeLaterChecksAndKeepWhatWasReached) {
  const StepStatistics statistics;
  AccuracyGuard guard;
  EXPECT_EQ(guard.check(0.0, made_up(100.0, 0.05), statistics), AccuracyLevel::kWarn);  // 5e-4 > 1e-4
  AccuracyRequirements looser;
  looser.energy_balance_relative = {true, 1e-3, 1e-1};
  guard.set_requirements(looser);
  EXPECT_EQ(guard.check(1.0, made_up(100.0, 0.05), statistics), AccuracyLevel::kOk);  // now fine
  EXPECT_EQ(guard.level(), AccuracyLevel::kWarn);                                     // the WARN reached stays
  AccuracyRequirements bad = looser;
  bad.constraint = {true, 1.0, 1e-3};
  EXPECT_THROW(guard.set_requirements(bad), std::invalid_argument);
  EXPECT_EQ(guard.requirements().constraint.warn, looser.constraint.warn);  // unchanged
}

TEST(AccuracyGuard, EveryQuantityTripsOnItsOwnLimitAndNonFiniteIsAlwaysError) {
  AccuracyRequirements requirements;
  requirements.p2_balance = {true, 1e-8, 1e-6};
  requirements.estimated_error = {true, 1e-6, 1e-3};
  const StepStatistics no_estimate;
  {
    AccuracyGuard guard(requirements);
    EXPECT_EQ(guard.check(0.0, made_up(1.0, 0.0, 1e-7), no_estimate), AccuracyLevel::kWarn);
    EXPECT_EQ(guard.events().back().quantity, AccuracyQuantity::kP2Balance);
  }
  {
    AccuracyGuard guard(requirements);
    EXPECT_EQ(guard.check(0.0, made_up(1.0, 0.0, 0.0, 1e-5), no_estimate), AccuracyLevel::kError);
    ASSERT_EQ(guard.events().size(), 2u);  // straight to ERROR: WARN passed at the same check
    EXPECT_EQ(guard.events()[0].level, AccuracyLevel::kWarn);
    EXPECT_EQ(guard.events().back().quantity, AccuracyQuantity::kConstraint);
    EXPECT_NE(guard.summary().find("constraint"), std::string::npos);
  }
  {
    AccuracyGuard guard(requirements);
    StepStatistics statistics;
    for (int step = 0; step < 3; ++step) record_local_error_estimate(statistics, 4e-4);  // Σ ê = 1.2e-3
    EXPECT_EQ(guard.check(0.0, made_up(1.0, 0.0), statistics), AccuracyLevel::kError);
    EXPECT_EQ(guard.events().back().quantity, AccuracyQuantity::kEstimatedError);
  }
  {
    AccuracyGuard guard(requirements);
    EXPECT_EQ(guard.check(0.5, made_up(std::numeric_limits<double>::infinity(), 0.0), no_estimate),
              AccuracyLevel::kError);
    EXPECT_EQ(guard.events().back().quantity, AccuracyQuantity::kNonFinite);
    EXPECT_NE(guard.summary().find("non_finite"), std::string::npos);
  }
  {
    AccuracyRequirements off;
    off.energy_balance_relative.enabled = false;
    off.constraint.enabled = false;
    AccuracyGuard guard(off);
    EXPECT_EQ(guard.check(0.0, made_up(1.0, 0.9, 5.0, 5.0), no_estimate), AccuracyLevel::kOk);
    EXPECT_EQ(guard.check(0.0, made_up(1.0, std::nan("")), no_estimate), AccuracyLevel::kError);  // NaN: never silent
  }
}

TEST(AccuracyGuard, RefusesLimitsThatAreNotZeroLessThanWarnLessOrEqualError) {
  AccuracyRequirements requirements;
  requirements.p2_balance = {true, 1e-3, 1e-6};
  EXPECT_THROW(AccuracyGuard{requirements}, std::invalid_argument);
  requirements.p2_balance = {true, 0.0, 1e-6};
  EXPECT_THROW(AccuracyGuard{requirements}, std::invalid_argument);
  requirements.p2_balance = {true, 1e-6, std::numeric_limits<double>::infinity()};
  EXPECT_THROW(AccuracyGuard{requirements}, std::invalid_argument);
}

std::string write_scene(const std::string& name, const std::string& text) {
  const std::string path = temp_path(name + ".yaml");
  std::ofstream(path) << text;
  return path;
}

TEST(AccuracyGuardScene, ReadsLimitsAndOffAndRefusesBadOnesNamingTheKey) {
  const std::string base = read_file(scene_path("free_coast"));
  ASSERT_FALSE(base.empty());
  const Scene defaults = load_scene(scene_path("free_coast"));
  EXPECT_TRUE(defaults.accuracy.energy_balance_relative.enabled);
  EXPECT_FALSE(defaults.accuracy.p2_balance.enabled);

  EXPECT_FALSE(defaults.accuracy.energy_balance.enabled);

  const std::string path = write_scene(
      "limits", base + "\naccuracy:\n  energy_balance_relative: off\n  p2_balance: {warn: 1.0e-9, error: 1.0e-7}\n"
                       "  energy_balance: {warn: 1.0e-6, error: 1.0e-3}\n");
  const Scene scene = load_scene(path);
  EXPECT_TRUE(scene.accuracy.energy_balance.enabled);
  EXPECT_EQ(scene.accuracy.energy_balance.warn, 1e-6);
  EXPECT_FALSE(scene.accuracy.energy_balance_relative.enabled);
  EXPECT_TRUE(scene.accuracy.p2_balance.enabled);
  EXPECT_EQ(scene.accuracy.p2_balance.warn, 1e-9);
  EXPECT_EQ(scene.accuracy.p2_balance.error, 1e-7);
  EXPECT_TRUE(scene.accuracy.constraint.enabled);  // untouched keys keep their defaults
  std::remove(path.c_str());

  const std::vector<std::pair<std::string, std::string>> bad = {
      {"  p2_balance: {warn: 1.0e-3, error: 1.0e-6}\n", "accuracy.p2_balance.warn"},
      {"  p2_balance: {warn: -1.0, error: 1.0e-6}\n", "accuracy.p2_balance.warn"},
      {"  p2_balance: {warn: 1.0e-6}\n", "accuracy.p2_balance.error"},
      {"  p2_balance: 1.0e-6\n", "accuracy.p2_balance"},
      {"  p2_balance: {warn: 1.0e-6, error: 1.0e-3, fatal: 1.0}\n", "accuracy.p2_balance.fatal"},
      {"  energy_error: off\n", "accuracy.energy_error"},
      {"  energy_balance: {warn: 1.0, error: 1.0e-3}\n", "accuracy.energy_balance.warn"},
  };
  for (const auto& [lines, key] : bad) {
    const std::string bad_path = write_scene("bad", base + "\naccuracy:\n" + lines);
    try {
      load_scene(bad_path);
      ADD_FAILURE() << "accepted: " << lines;
    } catch (const SceneError& error) {
      EXPECT_EQ(error.key(), key) << error.what();
    }
    std::remove(bad_path.c_str());
  }
}

/// jackknife_whirl with a 2 cm wheelbase, run with rk4 at the scene's own step (1 ms): a new
/// user's "short cart" whose energy ends 92 % low.
Scene short_wheelbase_whirl() {
  std::string text = read_file(scene_path("jackknife_whirl"));
  text = replaced_once(text, "wheelbase: 1.05 ", "wheelbase: 0.02 ");
  text = replaced_once(text, "name: birkhoff2 ", "name: rk4 ");
  const std::string path = write_scene("short_wheelbase_whirl", text);
  Scene scene = load_scene(path);
  std::remove(path.c_str());
  return scene;
}

/// Runs `scene` to its end, checking the guard at every output instant as cart_simulate does.
AccuracyGuard run_with_guard(const Scene& scene) {
  Simulation simulation(scene);
  AccuracyGuard guard(scene.accuracy);
  guard.check(simulation.state().time, simulation.diagnostics(), simulation.statistics());
  const long steps_per_row = std::lround(1.0 / (scene.output_rate * scene.integrator.step_size));
  long steps = 0;
  while (simulation.state().time + 0.5 * scene.integrator.step_size < simulation.end_time()) {
    simulation.step();
    if (++steps % steps_per_row == 0) guard.check(simulation.state().time, simulation.diagnostics(), simulation.statistics());
  }
  guard.check(simulation.state().time, simulation.diagnostics(), simulation.statistics());
  return guard;
}

TEST(AccuracyGuardRun, CatchesTheShortWheelbaseRk4RunWithItsEnergyError) {
  const AccuracyGuard guard = run_with_guard(short_wheelbase_whirl());
  EXPECT_EQ(guard.level(), AccuracyLevel::kError);
  const AccuracyEvent* first = guard.first_worst_event();
  ASSERT_NE(first, nullptr);
  EXPECT_EQ(first->quantity, AccuracyQuantity::kEnergyBalanceRelative);
  EXPECT_GT(guard.current_value(AccuracyQuantity::kEnergyBalanceRelative), 0.9);  // the 92 % at the end
  ASSERT_GE(guard.events().size(), 2u);  // WARN is recorded first, at an earlier or the same check
  EXPECT_EQ(guard.events()[0].level, AccuracyLevel::kWarn);
  EXPECT_LE(guard.events()[0].time, first->time);
  std::printf("short-wheelbase rk4 whirl: %s\n", guard.summary().c_str());
}

TEST(AccuracyGuardRun, NoShippedSceneRaisesAnAlarmWithItsOwnIntegrator) {
  // Every file of config/scenes/; docs/accuracy.md §2 quotes the largest residuals (two digits).
  std::set<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(std::string(BIRKHOFF_CART_SOURCE_DIR) + "/config/scenes")) {
    if (entry.path().extension() == ".yaml") names.insert(entry.path().stem().string());
  }
  ASSERT_GE(names.size(), 11u);
  double largest_energy = 0.0;      // relative [-]
  double largest_constraint = 0.0;  // [m/s]
  for (const std::string& name : names) {
    const AccuracyGuard guard = run_with_guard(load_scene(scene_path(name)));
    EXPECT_EQ(guard.level(), AccuracyLevel::kOk) << name << ": " << guard.summary();
    std::printf("%-19s energy_balance_relative max %.2e, constraint max %.2e m/s\n", name.c_str(),
                guard.largest_value(AccuracyQuantity::kEnergyBalanceRelative),
                guard.largest_value(AccuracyQuantity::kConstraint));
    largest_energy = std::max(largest_energy, guard.largest_value(AccuracyQuantity::kEnergyBalanceRelative));
    largest_constraint = std::max(largest_constraint, guard.largest_value(AccuracyQuantity::kConstraint));
  }
  EXPECT_TRUE(birkhoff_cart_test::page_figure_agrees("docs/accuracy.md", "the largest relative energy residual is ", 0,
                                                     largest_energy, 0.06));
  EXPECT_TRUE(birkhoff_cart_test::page_bound_holds("docs/accuracy.md", "the largest constraint residual stays\nbelow ", 0,
                                                   largest_constraint));
}

struct CliRun {
  int exit_status = -1;
  std::string standard_output;
  std::string standard_error;
};

CliRun run_cli(const std::string& arguments) {
  const std::string out = temp_path("stdout.txt");
  const std::string err = temp_path("stderr.txt");
  const std::string command = "'" + birkhoff_cart_test::cart_simulate_path() + "' " + arguments + " > '" + out +
                              "' 2> '" + err + "'";
  const int status = std::system(command.c_str());
  CliRun run;
  run.exit_status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  run.standard_output = read_file(out);
  run.standard_error = read_file(err);
  std::remove(out.c_str());
  std::remove(err.c_str());
  return run;
}

TEST(AccuracyGuardCli, ShortWheelbaseRunExitsFiveNamingTheQuantityUnlessAskedOnlyToWarn) {
  std::string text = read_file(scene_path("jackknife_whirl"));
  text = replaced_once(text, "wheelbase: 1.05 ", "wheelbase: 0.02 ");
  const std::string scene = write_scene("cli_short", text);
  const std::string csv = temp_path("cli_short.csv");
  const CliRun failing = run_cli("--scene '" + scene + "' --integrator rk4 --output '" + csv + "'");
  EXPECT_EQ(failing.exit_status, 5) << failing.standard_error;
  EXPECT_NE(failing.standard_output.find("accuracy: ERROR: energy_balance_relative"), std::string::npos)
      << failing.standard_output;
  EXPECT_NE(failing.standard_error.find("energy_balance_relative"), std::string::npos) << failing.standard_error;
  EXPECT_NE(failing.standard_output.find("local error estimate: last"), std::string::npos) << failing.standard_output;

  const CliRun warning =
      run_cli("--scene '" + scene + "' --integrator rk4 --on-accuracy-error warn --output '" + csv + "'");
  EXPECT_EQ(warning.exit_status, 0) << warning.standard_error;
  EXPECT_NE(warning.standard_output.find("accuracy: ERROR"), std::string::npos) << warning.standard_output;

  const CliRun healthy = run_cli("--scene '" + scene_path("jackknife_whirl") + "' --integrator rk4 --output '" + csv + "'");
  EXPECT_EQ(healthy.exit_status, 0) << healthy.standard_error;
  EXPECT_NE(healthy.standard_output.find("accuracy: OK"), std::string::npos) << healthy.standard_output;

  const CliRun bad = run_cli("--scene '" + scene + "' --on-accuracy-error ignore --output '" + csv + "'");
  EXPECT_EQ(bad.exit_status, 2);
  std::remove(scene.c_str());
  std::remove(csv.c_str());
}

}  // namespace
}  // namespace birkhoff_cart
