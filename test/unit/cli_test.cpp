// cart_simulate, the batch CLI, run as a separate process (it lives next to this test binary in
// devel/lib/birkhoff_cart/): CSV format, row times, numbers identical to an in-process Simulation
// run, and its error paths (usage, unknown integrator, scene errors, a failing step).
#include <gtest/gtest.h>

#include <cmath>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "birkhoff_cart/core/cart_binding/cart_stepper.h"
#include "birkhoff_cart/core/scene/scene.h"
#include "birkhoff_cart/core/run/simulation.h"
#include "test_scenes.h"

namespace birkhoff_cart {
namespace {

const char* const kHeader = "t,x,y,theta,chi,phi1,phi2,phi3,phi4,pi1,omega1,omega2,energy,p2,local_error_estimate";

using birkhoff_cart_test::CliOutcome;
using birkhoff_cart_test::read_file;
using birkhoff_cart_test::scene_path;

std::string temp_path(const std::string& name) {
  return ::testing::TempDir() + "cli_test_" + std::to_string(getpid()) + "_" + name;
}

/// Runs cart_simulate (next to this test binary) with `arguments`, capturing stderr.
CliOutcome run_cli(const std::string& arguments) {
  return birkhoff_cart_test::run_cart_simulate(arguments, temp_path("stderr.txt"));
}

std::vector<std::string> read_lines(const std::string& path) {
  std::ifstream file(path);
  std::vector<std::string> lines;
  for (std::string line; std::getline(file, line);) lines.push_back(line);
  return lines;
}

std::vector<double> parse_row(const std::string& line) {
  std::vector<double> values;
  std::stringstream stream(line);
  for (std::string field; std::getline(stream, field, ',');) values.push_back(std::strtod(field.c_str(), nullptr));
  return values;
}

/// The state columns t … p2 the CLI must write at output instant `time`.
std::vector<double> state_columns(double time, const Simulation& simulation) {
  const CartState& s = simulation.state();
  return {time,
          s.x,
          s.y,
          s.heading,
          s.steering_angle,
          s.wheel_spin_angle[0],
          s.wheel_spin_angle[1],
          s.wheel_spin_angle[2],
          s.wheel_spin_angle[3],
          s.arc_length,
          s.forward_speed,
          s.steering_rate,
          simulation.model().energy(s),
          simulation.model().steering_momentum(s)};
}

/// The row the CLI must write for `state` at output instant `time` (the last field, the local
/// error estimate, is empty before the first step and for integrators without one: no value).
std::vector<double> expected_row(double time, const Simulation& simulation) {
  std::vector<double> row = state_columns(time, simulation);
  if (has_local_error_estimate(simulation.statistics())) {
    row.push_back(simulation.statistics().local_error_estimate_last_step);
  }
  return row;
}

/// Runs the scene in-process and compares every CSV row with it, bit for bit.
void expect_matches_simulation(const Scene& scene, const std::vector<std::string>& lines, int expected_rows) {
  ASSERT_EQ(static_cast<int>(lines.size()), expected_rows + 1);
  EXPECT_EQ(lines[0], kHeader);
  Simulation simulation(scene);
  const long steps_per_row = std::lround(1.0 / (scene.output_rate * scene.integrator.step_size));
  for (int k = 0; k < expected_rows; ++k) {
    if (k > 0) {
      for (long n = 0; n < steps_per_row; ++n) simulation.step();
    }
    const double time = scene.initial_state.time + static_cast<double>(k) / scene.output_rate;
    const std::vector<double> row = parse_row(lines[k + 1]);
    const std::vector<double> expected = expected_row(time, simulation);
    ASSERT_EQ(row.size(), expected.size()) << "row " << k;
    for (std::size_t column = 0; column < row.size(); ++column) {
      ASSERT_EQ(row[column], expected[column]) << "row " << k << " column " << column;  // %.17g round-trips
    }
  }
}

TEST(CartSimulate, FreeCoastCsvMatchesASimulationRunBitForBit) {
  const std::string output = temp_path("free_coast.csv");
  const CliOutcome outcome = run_cli("--scene '" + scene_path("free_coast") + "' --output '" + output + "'");
  ASSERT_EQ(outcome.exit_status, 0) << outcome.standard_error;
  const std::vector<std::string> lines = read_lines(output);
  const Scene scene = load_scene(scene_path("free_coast"));  // 6 s at 100 Hz: 601 rows
  ASSERT_EQ(lines.size(), 602u);
  EXPECT_EQ(parse_row(lines[1])[0], 0.0);
  EXPECT_EQ(parse_row(lines.back())[0], 6.0);
  expect_matches_simulation(scene, lines, 601);
  // free_coast runs birkhoff2: its local error estimate fills the last column after the first row.
  const std::vector<double> last = parse_row(lines.back());
  ASSERT_EQ(last.size(), 15u);
  EXPECT_TRUE(std::isfinite(last[14]) && last[14] >= 0.0) << last[14];
  std::remove(output.c_str());
}

TEST(CartSimulate, CommandLineOverridesTheScene) {
  const std::string output = temp_path("overrides.csv");
  const CliOutcome outcome =
      run_cli("--scene '" + scene_path("free_coast") +
              "' --integrator rk4 --step 2e-3 --output-rate 50 --duration 1 --birkhoffian-form paper --output '" +
              output + "'");
  ASSERT_EQ(outcome.exit_status, 0) << outcome.standard_error;
  Scene scene = load_scene(scene_path("free_coast"));
  scene.integrator.name = "rk4";
  scene.integrator.step_size = 2e-3;
  scene.integrator.birkhoffian_form = BirkhoffianForm::kPaper;
  scene.output_rate = 50.0;
  scene.duration = 1.0;
  const std::vector<std::string> lines = read_lines(output);
  EXPECT_EQ(parse_row(lines.back())[0], 1.0);
  expect_matches_simulation(scene, lines, 51);
  std::remove(output.c_str());
}

// Every option also takes the form --option=value: the same run, byte for byte.
TEST(CartSimulate, OptionEqualsValueIsTheSameAsOptionValue) {
  const std::string separate = temp_path("separate.csv");
  const std::string joined = temp_path("joined.csv");
  const CliOutcome first = run_cli("--scene '" + scene_path("free_coast") +
                                   "' --integrator rk4 --step 2e-3 --output-rate 50 --duration 1 --quiet --output '" +
                                   separate + "'");
  const CliOutcome second = run_cli("--scene='" + scene_path("free_coast") +
                                    "' --integrator=rk4 --step=2e-3 --output-rate=50 --duration=1 --quiet --output='" +
                                    joined + "'");
  ASSERT_EQ(first.exit_status, 0) << first.standard_error;
  ASSERT_EQ(second.exit_status, 0) << second.standard_error;
  EXPECT_EQ(read_lines(separate).size(), 52u);  // the header and 51 rows
  EXPECT_EQ(read_file(separate), read_file(joined));
  for (const std::string& bad : {std::string(" --quiet=yes"), std::string(" --step="), std::string(" --stpe=0.01")}) {
    const CliOutcome refused =
        run_cli("--scene '" + scene_path("free_coast") + "' --output '" + temp_path("never.csv") + "'" + bad);
    EXPECT_EQ(refused.exit_status, 2) << bad;
    EXPECT_NE(refused.standard_error.find(bad == " --quiet=yes" ? "--quiet takes no value"
                                          : bad == " --step="    ? "--step needs a finite number > 0"
                                                                 : "unknown argument '--stpe=0.01'"),
              std::string::npos)
        << refused.standard_error;
  }
  std::remove(separate.c_str());
  std::remove(joined.c_str());
}

// --tolerance is dopri5's local tolerance: with a fixed-step member it would change nothing, so it
// is refused by name (whatever its value, 1e-30 too), not silently ignored.
TEST(CartSimulate, ToleranceWithAFixedStepMemberIsRefused) {
  for (const std::string value : {"1e-8", "1e-30"}) {
    const CliOutcome outcome = run_cli("--scene '" + scene_path("free_coast") +
                                       "' --integrator birkhoff_gauss4 --tolerance " + value + " --output '" +
                                       temp_path("never.csv") + "'");
    EXPECT_EQ(outcome.exit_status, 2) << value;
    EXPECT_NE(outcome.standard_error.find("option --tolerance is dopri5's local tolerance [-]; birkhoff_gauss4 steps "
                                          "at --step H"),
              std::string::npos)
        << outcome.standard_error;
    EXPECT_NE(outcome.standard_error.find("--step-control adaptive or reversible --position-tolerance M"),
              std::string::npos)
        << outcome.standard_error;
  }
  const CliOutcome dopri5 = run_cli("--scene '" + scene_path("free_coast") +
                                    "' --integrator dopri5 --tolerance 1e-8 --duration 1 --quiet --output '" +
                                    temp_path("dopri5.csv") + "'");
  EXPECT_EQ(dopri5.exit_status, 0) << dopri5.standard_error;
  std::remove(temp_path("dopri5.csv").c_str());
}

// The paper's eᵗ form drifts like exp(t h²/12) (docs/birkhoffian.md §9): a run long enough for the
// momenta to drift by more than 0.1 % is warned about on stderr, and still runs; a short one and
// the autonomous form are not.
TEST(CartSimulate, WarnsWhenAPaperFormRunIsLongEnoughToDrift) {
  const std::string output = temp_path("drift.csv");
  const std::string common = "--scene '" + scene_path("free_coast") + "' --integrator birkhoff2 --step 0.05 "
                             "--output-rate 1 --output '" + output + "'";
  const CliOutcome long_paper = run_cli(common + " --duration 200 --birkhoffian-form paper");
  // The drift is real: the accuracy guard measures it too (energy balance past 1 % of T*) and the
  // run exits 5 (docs/accuracy.md §2).
  EXPECT_EQ(long_paper.exit_status, 5) << long_paper.standard_error;
  EXPECT_NE(long_paper.standard_error.find("accuracy ERROR: energy_balance_relative"), std::string::npos)
      << long_paper.standard_error;
  EXPECT_NE(long_paper.standard_error.find("cart_simulate: warning: the paper's e^t form with birkhoff2"),
            std::string::npos)
      << long_paper.standard_error;
  EXPECT_NE(long_paper.standard_error.find("autonomous"), std::string::npos) << long_paper.standard_error;
  const CliOutcome short_paper = run_cli(common + " --duration 2 --birkhoffian-form paper");
  EXPECT_EQ(short_paper.exit_status, 0);
  EXPECT_EQ(short_paper.standard_error, "");
  const CliOutcome long_autonomous = run_cli(common + " --duration 200 --birkhoffian-form autonomous");
  EXPECT_EQ(long_autonomous.exit_status, 0);
  EXPECT_EQ(long_autonomous.standard_error, "");
  std::remove(output.c_str());
}

TEST(CartSimulate, BadArgumentsExitNonZeroWithUsage) {
  const std::string scene = "--scene '" + scene_path("free_coast") + "'";
  const std::string output = "--output '" + temp_path("never.csv") + "'";
  const std::string both = scene + " " + output;
  const std::vector<std::string> bad_arguments = {
      "", scene, output, both + " --frobnicate 1", both + " --step abc", both + " --step 0",
      both + " --duration -2", both + " --step", both + " --birkhoffian-form lagrangian"};
  for (const std::string& arguments : bad_arguments) {
    const CliOutcome outcome = run_cli(arguments);
    EXPECT_NE(outcome.exit_status, 0) << arguments;
    EXPECT_NE(outcome.standard_error.find("usage: cart_simulate"), std::string::npos) << arguments;
  }
}

TEST(CartSimulate, UnknownIntegratorNamesTheKnownOnes) {
  const CliOutcome outcome = run_cli("--scene '" + scene_path("free_coast") + "' --integrator euler --output '" +
                                  temp_path("never.csv") + "'");
  EXPECT_NE(outcome.exit_status, 0);
  EXPECT_NE(outcome.standard_error.find("euler"), std::string::npos) << outcome.standard_error;
  for (const std::string& name : integrator_names()) {
    EXPECT_NE(outcome.standard_error.find(name), std::string::npos) << outcome.standard_error;
  }
}

TEST(CartSimulate, SceneErrorIsOneLineNamingTheFile) {
  const std::string missing = temp_path("no_such_scene.yaml");
  const CliOutcome outcome = run_cli("--scene '" + missing + "' --output '" + temp_path("never.csv") + "'");
  EXPECT_NE(outcome.exit_status, 0);
  EXPECT_NE(outcome.standard_error.find(missing), std::string::npos) << outcome.standard_error;
  EXPECT_EQ(outcome.standard_error.find('\n'), outcome.standard_error.size() - 1) << outcome.standard_error;
}

TEST(CartSimulate, OutputIntervalMustBeWholeSteps) {
  const CliOutcome outcome = run_cli("--scene '" + scene_path("free_coast") + "' --step 3e-3 --output '" +
                                  temp_path("never.csv") + "'");
  EXPECT_NE(outcome.exit_status, 0);
  EXPECT_NE(outcome.standard_error.find("not a whole number of steps"), std::string::npos) << outcome.standard_error;
}

TEST(CartSimulate, FailingStepKeepsTheRowsWrittenAndNamesTheTime) {
  // The paper's special case started on χ = 0, where its mass matrix is singular: the first step
  // fails after the initial row was written.
  std::string text = read_file(scene_path("paper_special"));
  const std::string steering = "steering_angle: 1.5707963267948966";
  const std::string reference = "kind: paper_analytic";
  ASSERT_NE(text.find(steering), std::string::npos);
  ASSERT_NE(text.find(reference), std::string::npos);
  text.replace(text.find(steering), steering.size(), "steering_angle: 0.0");
  text.replace(text.find(reference), reference.size(), "kind: none");
  const std::string broken_scene = temp_path("singular.yaml");
  std::ofstream(broken_scene) << text;
  const std::string output = temp_path("singular.csv");
  const CliOutcome outcome = run_cli("--scene '" + broken_scene + "' --output '" + output + "'");
  EXPECT_NE(outcome.exit_status, 0);
  EXPECT_NE(outcome.standard_error.find("t = 1.5707963267948966"), std::string::npos) << outcome.standard_error;
  const std::vector<std::string> lines = read_lines(output);
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[0], kHeader);
  EXPECT_EQ(parse_row(lines[1])[0], 1.5707963267948966);
  std::remove(output.c_str());
  std::remove(broken_scene.c_str());
}

TEST(CartSimulate, PaperCaseEndsWithARowAtItsEndTimeOffTheOutputGrid) {
  // paper_special runs from π/2 to 3.0: 3 − π/2 is not a whole number of 1/100 s intervals, so
  // the rows are t0 + k/100 for k = 0..142 and one more at exactly t = 3.0 (a shorter last step).
  const std::string output = temp_path("paper_end.csv");
  const CliOutcome outcome = run_cli("--scene '" + scene_path("paper_special") + "' --output '" + output + "'");
  ASSERT_EQ(outcome.exit_status, 0) << outcome.standard_error;
  const std::vector<std::string> lines = read_lines(output);
  ASSERT_EQ(lines.size(), 1u + 143u + 1u);
  const std::vector<double> before_last = parse_row(lines[lines.size() - 2]);
  const std::vector<double> last = parse_row(lines.back());
  EXPECT_EQ(before_last[0], 1.5707963267948966 + 142.0 / 100.0);
  EXPECT_EQ(last[0], 3.0);
  constexpr double kArcLengthColumn = 9;
  constexpr double kRelativeTolerance = 1e-5;  // birkhoff2 at h = 1e-3 over 1.43 s [-]
  const double exact_arc_length = 1.0 + std::log(std::tan(1.5));  // π1(3) = 1 + ln tan(3/2) [m]
  EXPECT_NEAR(last[kArcLengthColumn], exact_arc_length, kRelativeTolerance * exact_arc_length);
  std::remove(output.c_str());
}

}  // namespace
}  // namespace birkhoff_cart
