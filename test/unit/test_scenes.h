// Scene texts and helpers shared by the unit tests that read scene files or run the batch CLI
// cart_simulate as a child process (bad_input_test, cli_test, hard_cases_test, scene_test).
// Header-only on purpose: every test/unit/*.cpp is its own executable, so a .cpp here would be
// taken for a test.
#pragma once

#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

namespace birkhoff_cart_test {

/// config/scenes/<name>.yaml in the source tree (a shipped scene).
inline std::string scene_path(const std::string& name) {
  return std::string(BIRKHOFF_CART_SOURCE_DIR) + "/config/scenes/" + name + ".yaml";
}

/// A minimal valid scene: every required key, no optional one. The cart is the shipped scenes'
/// default cart (docs/scenes.md), the start (χ, ω1, ω2) = (0.1 rad, 2.0 m/s, 0.3 rad/s), the
/// integrator rk4 at h = 0.01 s. `description` is the one-line description; `duration` [s] is
/// spelled as it appears in the file (e.g. "5.0"), since tests edit the text "duration: 5.0".
inline std::string minimal_scene(const std::string& description, const std::string& duration) {
  return "description: " + description + "\n" +
         R"(cart:
  wheelbase: 1.05
  rear_half_track: 0.55
  front_half_track: 0.5
  rear_wheel_radius: 0.14
  front_wheel_radius: 0.13
  rear_body_mass: 140.0
  rear_body_yaw_inertia: 30.0
  front_axle_mass: 12.0
  front_axle_yaw_inertia: 1.0
  rear_wheel_mass: 3.0
  rear_wheel_spin_inertia: 0.03
  rear_wheel_yaw_inertia: 0.025
  front_wheel_mass: 2.2
  front_wheel_spin_inertia: 0.019
  front_wheel_yaw_inertia: 0.013
  gravity: 9.81
initial_state:
  steering_angle: 0.1
  forward_speed: 2.0
  steering_rate: 0.3
)" + "duration: " + duration + "\n" +
         R"(integrator:
  name: rk4
  step_size: 0.01
)";
}

/// `text` with its first `from` replaced by `to`; a `from` that does not occur is a test failure
/// (and the text comes back unchanged).
inline std::string replaced_once(std::string text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

/// The whole content of the file at `path` ("" when it cannot be read).
inline std::string read_file(const std::string& path) {
  std::ifstream file(path);
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

/// The directory of this test executable (devel/lib/birkhoff_cart/), from /proc/self/exe; "."
/// when it cannot be read.
inline std::string directory_of_this_binary() {
  std::array<char, 4096> path{};
  const ssize_t length = ::readlink("/proc/self/exe", path.data(), path.size() - 1);
  if (length <= 0) return ".";
  const std::string full(path.data(), static_cast<std::size_t>(length));
  return full.substr(0, full.rfind('/'));
}

/// The batch CLI, built next to the unit tests.
inline std::string cart_simulate_path() { return directory_of_this_binary() + "/cart_simulate"; }

/// Everything `command` (run through the shell) writes to stdout.
inline std::string standard_output_of(const std::string& command) {
  std::string output;
  FILE* pipe = ::popen(command.c_str(), "r");
  if (pipe == nullptr) return output;
  char buffer[4096];
  std::size_t count = 0;
  while ((count = std::fread(buffer, 1, sizeof buffer, pipe)) > 0) output.append(buffer, count);
  ::pclose(pipe);
  return output;
}

/// What a cart_simulate run left: its exit status (−1 when it died of a signal) and its stderr.
struct CliOutcome {
  int exit_status = -1;
  std::string standard_error;
};

/// Runs cart_simulate through the shell with `arguments` (shell-quoted by the caller), stdout
/// discarded (cart_simulate writes only to its --output file and stderr), stderr captured through
/// the file `stderr_path`, which is removed afterwards.
inline CliOutcome run_cart_simulate(const std::string& arguments, const std::string& stderr_path) {
  const std::string command =
      "'" + cart_simulate_path() + "' " + arguments + " 2> '" + stderr_path + "' > /dev/null";
  CliOutcome outcome;
  const int status = std::system(command.c_str());
  outcome.exit_status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  outcome.standard_error = read_file(stderr_path);
  std::remove(stderr_path.c_str());
  return outcome;
}

/// What a cart_simulate run printed: its exit status (−1 when it died of a signal), stdout and stderr.
struct CliPrinted {
  int exit_status = -1;  ///< 124: killed by timeout
  std::string standard_output, standard_error;
};

/// Runs cart_simulate through the shell with `arguments` (shell-quoted by the caller), under
/// `timeout time_limit` when it is > 0 [s], capturing stdout and stderr through the files
/// `scratch` + "stdout.txt" and + "stderr.txt", which are removed afterwards.
inline CliPrinted run_cart_simulate_printing(const std::string& arguments, const std::string& scratch,
                                            int time_limit = 0) {
  const std::string out = scratch + "stdout.txt", err = scratch + "stderr.txt";
  const std::string command = (time_limit > 0 ? "timeout " + std::to_string(time_limit) + " " : std::string()) + "'" +
                              cart_simulate_path() + "' " + arguments + " > '" + out + "' 2> '" + err + "'";
  const int status = std::system(command.c_str());
  CliPrinted printed;
  printed.exit_status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  printed.standard_output = read_file(out);
  printed.standard_error = read_file(err);
  std::remove(out.c_str());
  std::remove(err.c_str());
  return printed;
}

}  // namespace birkhoff_cart_test
