// The mutation kill list cannot rot unnoticed: every named mutation of checks/mutation_check.py
// must still apply (its target text occurs exactly once), checked in seconds on every test run;
// and a target moved by a refactoring is reported by name, as it would be in CI.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace {

const std::string kSourceDirectory = BIRKHOFF_CART_SOURCE_DIR;

struct Outcome {
  int exit_status = -1;
  std::string output;
};

Outcome run(const std::string& command) {
  Outcome outcome;
  FILE* pipe = ::popen((command + " 2>&1").c_str(), "r");
  if (pipe == nullptr) return outcome;
  char buffer[4096];
  std::size_t count = 0;
  while ((count = std::fread(buffer, 1, sizeof buffer, pipe)) > 0) outcome.output.append(buffer, count);
  const int status = ::pclose(pipe);
  outcome.exit_status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return outcome;
}

std::string check_targets(const std::string& root) {
  return "/usr/bin/python3 '" + kSourceDirectory + "/checks/mutation_check.py' --check-targets --root '" + root + "'";
}

TEST(MutationTargets, EveryMutationStillApplies) {
  const Outcome outcome = run(check_targets(kSourceDirectory));
  EXPECT_EQ(outcome.exit_status, 0) << outcome.output;
  EXPECT_NE(outcome.output.find("mutation targets apply"), std::string::npos) << outcome.output;
  // At least 15 named mutations (docs/developing.md, "Mutation check").
  int listed = 0;
  std::istringstream lines(run("/usr/bin/python3 '" + kSourceDirectory + "/checks/mutation_check.py' --list").output);
  for (std::string line; std::getline(lines, line);) listed += line.find(": ") != std::string::npos;
  EXPECT_GE(listed, 15);
}

TEST(MutationTargets, AMovedTargetIsReportedByName) {
  namespace fs = std::filesystem;
  const fs::path copy = fs::temp_directory_path() / ("mutation_targets_test_" + std::to_string(::getpid()));
  fs::remove_all(copy);
  fs::create_directories(copy);
  for (const char* part : {"include", "src"}) {
    // The real directories (the workspace links to them), copied file by file: the copy is edited.
    fs::copy(fs::canonical(fs::path(kSourceDirectory) / part), copy / part, fs::copy_options::recursive);
  }
  // A refactoring rewrites the turn count of the angle reduction.
  const fs::path header = copy / "include/birkhoff_cart/core/integrators/angle_reduction.h";
  std::stringstream text;
  text << std::ifstream(header).rdbuf();
  std::string source = text.str();
  const std::string target = "turns += k;";
  const auto at = source.find(target);
  ASSERT_NE(at, std::string::npos);
  source.replace(at, target.size(), "turns = turns + k;");
  std::ofstream(header) << source;

  const Outcome outcome = run(check_targets(copy.string()));
  EXPECT_EQ(outcome.exit_status, 1) << outcome.output;
  EXPECT_NE(outcome.output.find("STALE angle_reduction_turns: target found 0 times"), std::string::npos)
      << outcome.output;
  fs::remove_all(copy);
}

}  // namespace
