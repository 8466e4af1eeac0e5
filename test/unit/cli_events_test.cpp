// cart_simulate --event (docs/events.md): crossings printed on stdout at the paper's special case's
// closed-form times (chi = t; pi1 = 1 + ln tan(t/2)), the rows unchanged by watching, a terminal
// event ending the rows at its time, and bad events refused by name.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "test_scenes.h"

namespace birkhoff_cart {
namespace {

using birkhoff_cart_test::read_file;
using birkhoff_cart_test::scene_path;

const double kPi1CrossingTime = 2.0 * std::atan(std::exp(0.2));  // [s]: 1 + ln tan(t/2) = 1.2

std::string temp_path(const std::string& name) {
  return ::testing::TempDir() + "cli_events_test_" + std::to_string(getpid()) + "_" + name;
}

using Outcome = birkhoff_cart_test::CliPrinted;

Outcome run_cli(const std::string& arguments) {
  return birkhoff_cart_test::run_cart_simulate_printing(arguments, temp_path(""), 60);
}

/// The times of the lines "event NAME at t = T s: ..." in order.
std::vector<std::pair<std::string, double>> event_lines(const std::string& output) {
  std::vector<std::pair<std::string, double>> found;
  std::istringstream lines(output);
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("event ", 0) != 0) continue;
    const std::size_t at = line.find(" at t = ");
    found.emplace_back(line.substr(6, at - 6), std::strtod(line.c_str() + at + 8, nullptr));
  }
  return found;
}

const std::string kGauss8Fixed = " --integrator birkhoff_gauss8 --step 0.01 --quiet";

TEST(CartSimulateEvents, CrossingsArePrintedAtTheClosedFormsTimesAndLeaveTheRowsAsTheyWere) {
  const std::string watched = temp_path("watched.csv");
  const std::string plain = temp_path("plain.csv");
  const std::string rows = temp_path("events.csv");
  const Outcome outcome = run_cli("--scene '" + scene_path("paper_special") + "'" + kGauss8Fixed +
                                  " --event chi=2.5 --event pi1=1.2,rising --event=chi=2.5,falling --events-output '" +
                                  rows + "' --output '" + watched + "'");
  ASSERT_EQ(outcome.exit_status, 0) << outcome.standard_error;
  const auto events = event_lines(outcome.standard_output);
  ASSERT_EQ(events.size(), 2u) << outcome.standard_output;
  EXPECT_EQ(events[0].first, "pi1=1.2,rising");  // in time order
  EXPECT_NEAR(events[0].second, kPi1CrossingTime, 1e-10);
  EXPECT_EQ(events[1].first, "chi=2.5");
  EXPECT_NEAR(events[1].second, 2.5, 1e-10);
  EXPECT_NE(outcome.standard_output.find("cart_simulate summary"), std::string::npos);
  // The same crossings as CSV rows, in time order, with the state there (chi = t on the paper's case).
  std::istringstream csv(read_file(rows));
  std::string line;
  std::getline(csv, line);
  EXPECT_EQ(line, "event,occurrence,t,x,y,theta,chi,phi1,phi2,phi3,phi4,pi1,omega1,omega2");
  for (const auto& [name, time] : events) {
    ASSERT_TRUE(std::getline(csv, line));
    EXPECT_EQ(line.rfind("\"" + name + "\",1,", 0), 0u) << line;
    const std::size_t t_at = line.find(",1,") + 3;
    EXPECT_EQ(std::strtod(line.c_str() + t_at, nullptr), time) << line;
  }
  EXPECT_FALSE(std::getline(csv, line)) << line;
  std::remove(rows.c_str());
  ASSERT_EQ(run_cli("--scene '" + scene_path("paper_special") + "'" + kGauss8Fixed + " --output '" + plain + "'")
                .exit_status,
            0);
  EXPECT_EQ(read_file(watched), read_file(plain)) << "watching events changed the run";
  std::remove(watched.c_str());
  std::remove(plain.c_str());
}

TEST(CartSimulateEvents, ATerminalEventEndsTheRowsAtItsTime) {
  for (const std::string& control :
       std::vector<std::string>{kGauss8Fixed, std::string(" --integrator birkhoff_gauss8 --step-control adaptive --position-tolerance 1e-10 "
                                  "--quiet")}) {
    const std::string output = temp_path("terminal.csv");
    const Outcome outcome = run_cli("--scene '" + scene_path("paper_special") + "'" + control +
                                    " --event pi1=1.2,terminal --event chi=2.5 --output '" + output + "'");
    ASSERT_EQ(outcome.exit_status, 0) << outcome.standard_error;
    const auto events = event_lines(outcome.standard_output);
    ASSERT_EQ(events.size(), 1u) << control << "\n" << outcome.standard_output;
    EXPECT_NEAR(events[0].second, kPi1CrossingTime, 1e-10) << control;
    EXPECT_NE(outcome.standard_output.find("stopped by the terminal event pi1=1.2,terminal"), std::string::npos)
        << outcome.standard_output;
    // Rows every 0.01 s from pi/2 up to the last output instant before the crossing, none after it.
    std::istringstream rows(read_file(output));
    std::string line, last;
    std::getline(rows, line);  // the header
    while (std::getline(rows, line)) last = line;
    const double last_time = std::strtod(last.c_str(), nullptr);
    EXPECT_LE(last_time, events[0].second) << control;
    EXPECT_GT(last_time, events[0].second - 0.01) << control << ": rows before the crossing are missing";
    std::remove(output.c_str());
  }
}

TEST(CartSimulateEvents, BadEventsAreRefusedByName) {
  const std::string output = temp_path("refused.csv");
  const Outcome malformed =
      run_cli("--scene '" + scene_path("paper_special") + "' --event speed=1 --output '" + output + "'");
  EXPECT_EQ(malformed.exit_status, 2);
  EXPECT_NE(malformed.standard_error.find("option --event: event 'speed=1': unknown state field 'speed'"),
            std::string::npos)
      << malformed.standard_error;
  const Outcome empty = run_cli("--scene '" + scene_path("paper_special") + "' --event= --output '" + output + "'");
  EXPECT_EQ(empty.exit_status, 2) << empty.standard_error;
  // Fixed steps with actuators have no states between steps to locate a crossing on.
  const Outcome actuated =
      run_cli("--scene '" + scene_path("steering_actuator") + "' --event chi=0.3 --output '" + output + "'");
  EXPECT_EQ(actuated.exit_status, 3);
  EXPECT_NE(actuated.standard_error.find("events at fixed steps"), std::string::npos) << actuated.standard_error;
  EXPECT_NE(actuated.standard_error.find("dopri5"), std::string::npos) << "no way out named: " << actuated.standard_error;
  const Outcome twice = run_cli("--scene '" + scene_path("paper_special") +
                                "' --event chi=2 --event chi=2 --output '" + output + "'");
  EXPECT_EQ(twice.exit_status, 2);
  EXPECT_NE(twice.standard_error.find("given twice"), std::string::npos) << twice.standard_error;
  std::remove(output.c_str());
}

}  // namespace
}  // namespace birkhoff_cart
