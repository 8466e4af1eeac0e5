// cart_simulate on the inputs most likely to abort, hang or freeze, and its self-help:
// every run ends with exit 0 and its last row at t0 + T, or exit 2/3/4 with a message naming the
// problem. Each run is bounded by `timeout` so that a regression to a hang fails instead of
// stalling the suite.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include "birkhoff_cart/core/cart_binding/cart_stepper.h"
#include "test_scenes.h"

namespace birkhoff_cart {
namespace {

using birkhoff_cart_test::cart_simulate_path;
using birkhoff_cart_test::read_file;
using birkhoff_cart_test::replaced_once;
using birkhoff_cart_test::scene_path;

constexpr int kRunBudget = 60;  // seconds a single run may take before `timeout` kills it [s]

std::string temp_path(const std::string& name) {
  return ::testing::TempDir() + "cli_robustness_" + std::to_string(getpid()) + "_" + name;
}

using Outcome = birkhoff_cart_test::CliPrinted;

Outcome run(const std::string& arguments) {
  return birkhoff_cart_test::run_cart_simulate_printing(arguments, temp_path(""), kRunBudget);
}

/// free_coast starting at `start_time` [s] (spelled as in YAML), written to a temporary file.
std::string free_coast_from(const std::string& start_time) {
  const std::string path = temp_path("free_coast_" + start_time + ".yaml");
  std::ofstream(path) << replaced_once(read_file(scene_path("free_coast")), "time: 0.0 ", "time: " + start_time + " ");
  return path;
}

std::string last_line(const std::string& path) {
  std::ifstream file(path);
  std::string line, last;
  while (std::getline(file, line)) last = line;
  return last;
}

double first_field(const std::string& line) { return std::strtod(line.c_str(), nullptr); }

TEST(CartSimulateRobustness, DurationsJustOffAMultipleOfTheStepEndAtTheirEndTime) {
  // Both aborted with std::terminate (exit 134) before the shared step schedule: the CLI's last
  // step allowed a remainder of h (1 + 1e-9), step_to only h (1 + 1e-12).
  struct Case {
    std::string start_time;  // t0 as written in the scene
    double start;            // t0 [s]
    std::string duration;    // --duration
    double length;           // T [s]
  };
  const std::vector<Case> cases = {{"1000.0", 1000.0, "0.051", 0.051},
                                   {"1.0", 1.0, "4.6960000000005", 4.6960000000005}};
  for (const Case& c : cases) {
    const std::string scene = free_coast_from(c.start_time), output = temp_path("near_multiple.csv");
    const Outcome outcome = run("--scene '" + scene + "' --duration " + c.duration + " --output '" + output + "'");
    EXPECT_EQ(outcome.exit_status, 0) << c.duration << ": " << outcome.standard_error;
    EXPECT_EQ(first_field(last_line(output)), c.start + c.length) << c.duration;
    std::remove(output.c_str());
    std::remove(scene.c_str());
  }
}

TEST(CartSimulateRobustness, AHugeDurationIsRefusedNamingTheKey) {
  // --duration 1e17: floor(T·rate) overflowed a long (UB) and the run never ended.
  const Outcome outcome =
      run("--scene '" + scene_path("free_coast") + "' --duration 1e17 --output '" + temp_path("never.csv") + "'");
  EXPECT_EQ(outcome.exit_status, 3) << outcome.standard_error;
  EXPECT_NE(outcome.standard_error.find("'duration (--duration)'"), std::string::npos) << outcome.standard_error;
  std::remove(temp_path("never.csv").c_str());
}

TEST(CartSimulateRobustness, AStartTimeWhereTimeWouldStandStillIsRefused) {
  // t0 = 1e300: t0 + n h = t0, every row had the same time and the forcing froze, exit 0.
  const std::string scene = free_coast_from("1.0e300");
  const Outcome outcome = run("--scene '" + scene + "' --duration 1 --output '" + temp_path("never.csv") + "'");
  EXPECT_EQ(outcome.exit_status, 3) << outcome.standard_error;
  EXPECT_NE(outcome.standard_error.find("'initial_state.time'"), std::string::npos) << outcome.standard_error;
  std::remove(scene.c_str());
  std::remove(temp_path("never.csv").c_str());
}

TEST(CartSimulateRobustness, ADopri5ToleranceBelowTheFloorIsRefused) {
  // 1e-24: 10 ms of scene time took 10.7 s, and smaller tolerances longer still; now refused.
  const Outcome outcome = run("--scene '" + scene_path("free_coast") +
                              "' --integrator dopri5 --tolerance 1e-24 --duration 0.01 --output '" +
                              temp_path("never.csv") + "'");
  EXPECT_EQ(outcome.exit_status, 3) << outcome.standard_error;
  EXPECT_NE(outcome.standard_error.find("dopri5 tolerance must be"), std::string::npos) << outcome.standard_error;
  std::remove(temp_path("never.csv").c_str());
}

TEST(CartSimulateRobustness, AnOutputRateOutOfReachIsRefusedNamingTheOutputRate) {
  // Under a step control h is the rows' interval 1/HZ: the time limits blamed a scene key and a step h
  // the user never gave (at t0 = 1e6 s, rows at 1e5 Hz are finer than the doubles there resolve).
  const std::string late = free_coast_from("1.0e6");
  const Outcome outcome = run("--scene '" + late +
                              "' --integrator birkhoff_gauss8 --step-control adaptive --position-tolerance 1e-6 "
                              "--output-rate 1e5 --output '" + temp_path("never.csv") + "'");
  EXPECT_EQ(outcome.exit_status, 3) << outcome.standard_error;
  EXPECT_NE(outcome.standard_error.find("(--output-rate): under a step control h is the rows' interval"),
            std::string::npos)
      << outcome.standard_error;
  std::remove(late.c_str());
  // A rate that asks for more than 1e8 rows is refused naming both: --output-rate 1e9 over 6 s
  // started 6e9 rows under a step control and filled the disk.
  for (const char* control : {"--step-control adaptive --position-tolerance 1e-6 ", "--step 1e-9 "}) {
    const Outcome flood = run("--scene '" + scene_path("free_coast") + "' --integrator birkhoff_gauss8 " + control +
                              "--output-rate 1e9 --output '" + temp_path("never.csv") + "'");
    EXPECT_EQ(flood.exit_status, 3) << control << flood.standard_error;
    EXPECT_NE(flood.standard_error.find("asks for 6000000001 rows, more than the limit"), std::string::npos)
        << control << flood.standard_error;
  }
  // A row interval beyond the run leaves the rows at its start and end, as at fixed steps.
  const std::string sparse = temp_path("sparse.csv");
  const Outcome beyond = run("--scene '" + scene_path("free_coast") +
                             "' --integrator birkhoff_gauss8 --step-control adaptive --position-tolerance 1e-6 "
                             "--output-rate 1e-6 --output '" + sparse + "'");
  EXPECT_EQ(beyond.exit_status, 0) << beyond.standard_error;
  EXPECT_EQ(first_field(last_line(sparse)), 6.0);
  std::remove(sparse.c_str());
  // At fixed steps a rate whose rows fall between the steps names both options.
  const Outcome fixed = run("--scene '" + scene_path("free_coast") + "' --output-rate 1e9 --output '" +
                            temp_path("never.csv") + "'");
  EXPECT_EQ(fixed.exit_status, 3) << fixed.standard_error;
  EXPECT_NE(fixed.standard_error.find("(--output-rate) puts rows between the fixed steps"), std::string::npos)
      << fixed.standard_error;
  std::remove(temp_path("never.csv").c_str());
}

TEST(CartSimulateRobustness, AnOutputRateWithAHugeStepCountIsRefused) {
  // 1/HZ = 1e300 s is 1e303 steps: lround of that was UB.
  const Outcome outcome = run("--scene '" + scene_path("free_coast") + "' --output-rate 1e-300 --output '" +
                              temp_path("never.csv") + "'");
  EXPECT_EQ(outcome.exit_status, 3) << outcome.standard_error;
  EXPECT_NE(outcome.standard_error.find("not a whole number of steps"), std::string::npos) << outcome.standard_error;
  std::remove(temp_path("never.csv").c_str());
}

TEST(CartSimulateRobustness, ScenesBeyondTheSizeCapAndEndlessInputAreRefusedByName) {
  // A 10 MB scene kept cart_simulate busy 13 s at ~950 MB before refusing it; endless input on
  // stdin ended in std::bad_alloc. Both are now refused by the core's bounded read (exit 3).
  const std::string big = temp_path("ten_megabytes.yaml");
  {
    std::ofstream file(big);
    file << read_file(scene_path("free_coast"));
    for (int line = 0; line < 100000; ++line) file << "# " << std::string(98, 'x') << "\n";  // 10 MB of comments
  }
  const Outcome too_big = run("--scene '" + big + "' --output '" + temp_path("never.csv") + "'");
  EXPECT_EQ(too_big.exit_status, 3) << too_big.standard_error;
  EXPECT_NE(too_big.standard_error.find("key '(file)': is 10"), std::string::npos) << too_big.standard_error;
  EXPECT_NE(too_big.standard_error.find("beyond the cap of 1048576 bytes"), std::string::npos) << too_big.standard_error;
  std::remove(big.c_str());
  const Outcome endless = run("--scene /dev/stdin --output '" + temp_path("never.csv") + "' < /dev/zero");
  EXPECT_EQ(endless.exit_status, 3) << endless.standard_error;
  EXPECT_NE(endless.standard_error.find("holds more than the cap of 1048576 bytes"), std::string::npos)
      << endless.standard_error;
  const Outcome directory = run("--scene '" + ::testing::TempDir() + "' --output '" + temp_path("never.csv") + "'");
  EXPECT_EQ(directory.exit_status, 3) << directory.standard_error;
  EXPECT_NE(directory.standard_error.find("is a directory"), std::string::npos) << directory.standard_error;
  std::remove(temp_path("never.csv").c_str());
}

TEST(CartSimulateRobustness, HelpAndVersionExitZeroOnStdout) {
  for (const char* option : {"--help", "-h"}) {
    const Outcome outcome = run(option);
    EXPECT_EQ(outcome.exit_status, 0) << option;
    EXPECT_EQ(outcome.standard_output.rfind("usage: cart_simulate", 0), 0u) << option;
    EXPECT_NE(outcome.standard_output.find("Exit status"), std::string::npos) << option;
    EXPECT_EQ(outcome.standard_error, "") << option;
    for (const std::string& name : integrator_names()) {  // every registry member is named
      EXPECT_NE(outcome.standard_output.find(name), std::string::npos) << name;
    }
  }
  const Outcome version = run("--version");
  EXPECT_EQ(version.exit_status, 0);
  EXPECT_EQ(version.standard_output.rfind("cart_simulate (birkhoff_cart) ", 0), 0u) << version.standard_output;
}

TEST(CartSimulateRobustness, AnUnwritableOutputIsRefused) {
  const Outcome outcome =
      run("--scene '" + scene_path("free_coast") + "' --output '" + temp_path("no_such_dir") + "/x.csv'");
  EXPECT_EQ(outcome.exit_status, 3);
  EXPECT_NE(outcome.standard_error.find("cannot write"), std::string::npos) << outcome.standard_error;
}

TEST(CartSimulateRobustness, AFullDiskStopsTheRunWithExit3) {
  if (access("/dev/full", W_OK) != 0) GTEST_SKIP() << "no writable /dev/full";
  const Outcome outcome = run("--scene '" + scene_path("free_coast") + "' --output /dev/full");
  EXPECT_EQ(outcome.exit_status, 3) << outcome.standard_error;
  EXPECT_NE(outcome.standard_error.find("writing the CSV failed"), std::string::npos) << outcome.standard_error;
}

}  // namespace
}  // namespace birkhoff_cart
