// The step-schedule rule (step_schedule.h) and the scene time limits: every run ends exactly at
// t0 + T, no step is a sliver or longer than (1 + 2e-5) h, Simulation follows the plan, and times
// where t + h would round (t0 = 1e300, t0 + T = 1e17) are refused with the key to blame.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <fstream>
#include <random>
#include <string>

#include "birkhoff_cart/core/scene/scene.h"
#include "birkhoff_cart/core/run/simulation.h"
#include "birkhoff_cart/core/scene/step_schedule.h"
#include "test_scenes.h"

namespace birkhoff_cart {
namespace {

using birkhoff_cart_test::read_file;
using birkhoff_cart_test::replaced_once;
using birkhoff_cart_test::scene_path;

constexpr double kLongestStep = 1.0 + 2.0 * kMinFinalStepFraction;  // longest step / h [-]

/// The schedule's invariants: N whole steps on the grid not past the end, a final step of
/// length in [kMinFinalStepFraction h, (1 + 2 kMinFinalStepFraction) h] onto the end, or an end on the grid.
void expect_valid(const StepSchedule& s, double t0, double duration, double h) {
  SCOPED_TRACE("t0 = " + std::to_string(t0) + ", T = " + std::to_string(duration) + ", h = " + std::to_string(h));
  EXPECT_EQ(s.end_time, t0 + duration);
  EXPECT_LE(s.grid_time(s.whole_steps), s.end_time);
  if (s.final_step) {
    const double last = s.end_time - s.grid_time(s.whole_steps);  // [s]
    EXPECT_GT(last, 0.0);
    EXPECT_LE(last, kLongestStep * h);
    if (s.whole_steps > 0) {
      EXPECT_GE(last, kMinFinalStepFraction * h);
    }
  } else {
    EXPECT_EQ(s.grid_time(s.whole_steps), s.end_time);
  }
}

TEST(StepSchedule, WholeRunOnTheGridHasNoFinalStep) {
  const StepSchedule s = plan_steps(0.0, 6.0, 1e-3);
  EXPECT_EQ(s.whole_steps, 6000u);
  EXPECT_FALSE(s.final_step);
  EXPECT_EQ(s.total_steps(), 6000u);
}

TEST(StepSchedule, EndOffTheGridGetsOneShorterFinalStep) {
  const double t0 = M_PI / 2.0;  // paper_special: π/2 … 3
  const StepSchedule s = plan_steps(t0, 3.0 - t0, 1e-3);
  EXPECT_EQ(s.whole_steps, 1429u);
  EXPECT_TRUE(s.final_step);
  EXPECT_EQ(s.end_time, 3.0);
  expect_valid(s, t0, 3.0 - t0, 1e-3);
}

TEST(StepSchedule, ASliverIsMergedIntoTheStepBefore) {
  // T = 4.6960000000005 s at h = 1 ms from t0 = 1 s : 5e-13 s past the grid.
  const StepSchedule s = plan_steps(1.0, 4.6960000000005, 1e-3);
  EXPECT_EQ(s.whole_steps, 4695u);
  EXPECT_TRUE(s.final_step);
  expect_valid(s, 1.0, 4.6960000000005, 1e-3);
}

TEST(StepSchedule, RandomRunsEndExactlyAtTheirEnd) {
  std::mt19937_64 random(17);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double steps[] = {1e-4, 2.5e-4, 1e-3, 2e-3, 5e-3, 1e-2, 0.1};
  int planned = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const double t0 = unit(random) < 0.2 ? 0.0 : std::pow(10.0, 6.0 * unit(random) - 1.0);  // 0, 0.1 … 1e5 s
    const double h = steps[random() % 7];
    double duration = std::pow(10.0, 4.5 * unit(random) - 3.0);  // 1 ms … 30 s
    if (trial % 2 == 0) {  // near a multiple of h, either side, by up to 1e-9 relative
      duration = std::max(1.0, std::round(duration / h)) * h * (1.0 + 1e-9 * (2.0 * unit(random) - 1.0));
    }
    StepSchedule s;
    try {
      s = plan_steps(t0, duration, h);
    } catch (const TimeLimitError& error) {
      continue;  // refused by name (a far t0 with a small h): fine here, checked below
    }
    ++planned;
    expect_valid(s, t0, duration, h);
    if (HasFailure()) return;
  }
  EXPECT_GT(planned, 19000);
}

TEST(StepSchedule, SimulationFollowsThePlanOntoTheEndTime) {
  // Two runs on which the CLI and the schedule once disagreed: t0 = 1000 s, T = 0.051 s; t0 = 1 s,
  // T = 4.6960000000005 s (shortened to its last 50 ms by starting at 5.646 s).
  const std::pair<double, double> runs[] = {{1000.0, 0.051}, {5.646, 4.6960000000005 + 1.0 - 5.646}};
  for (const auto& [t0, duration] : runs) {
    Scene scene = load_scene(scene_path("free_coast"));
    scene.initial_state.time = t0;
    scene.duration = duration;
    Simulation simulation(scene);
    std::uint64_t steps = 0;
    while (!simulation.at_end()) {
      simulation.step_on_schedule();
      ++steps;
    }
    EXPECT_EQ(simulation.state().time, t0 + duration);
    EXPECT_EQ(steps, simulation.schedule().total_steps());
    EXPECT_THROW(simulation.step_on_schedule(), std::logic_error);
    simulation.reset();
    EXPECT_FALSE(simulation.at_end());
  }
}

TEST(StepSchedule, TimesWhereTPlusHRoundsAreRefusedNamingTheKey) {
  try {
    plan_steps(1e300, 1.0, 1e-3);  // t + h = t: time would stand still 
    FAIL() << "t0 = 1e300 accepted";
  } catch (const TimeLimitError& error) {
    EXPECT_EQ(error.key(), "initial_state.time");
  }
  try {
    plan_steps(0.0, 1e17, 1e-3);  // 1e20 steps: floor(T·rate) overflowed a long (defect 3)
    FAIL() << "T = 1e17 s accepted";
  } catch (const TimeLimitError& error) {
    EXPECT_EQ(error.key(), "duration");
  }
  EXPECT_THROW(plan_steps(0.0, 1e-12, 1e-3), TimeLimitError);  // shorter than 1e-5 h
  EXPECT_THROW(plan_steps(NAN, 1.0, 1e-3), TimeLimitError);
  EXPECT_THROW(plan_steps(0.0, INFINITY, 1e-3), TimeLimitError);
  EXPECT_THROW(plan_steps(1e308, 1e308, 1e300), TimeLimitError);  // t0 + T overflows
  EXPECT_NO_THROW(plan_steps(1e6, 30.0, 1e-3));  // ~12 days in: still resolved
  EXPECT_NO_THROW(plan_steps(-50.0, 1.0, 1e-3));
}

TEST(StepSchedule, SceneLoaderRefusesAFarStartTimeAsASceneError) {
  const std::string text =
      replaced_once(read_file(scene_path("free_coast")), "time: 0.0 ", "time: 1.0e300 ");
  const std::string path = ::testing::TempDir() + "step_schedule_far_start.yaml";
  std::ofstream(path) << text;
  try {
    load_scene(path);
    FAIL() << "t0 = 1e300 loaded";
  } catch (const SceneError& error) {
    EXPECT_EQ(error.key(), "initial_state.time");
    EXPECT_NE(std::string(error.what()).find("too far from 0"), std::string::npos) << error.what();
  }
  std::remove(path.c_str());
}

TEST(StepSchedule, SimulationRefusesTheTimeLimitsAfterOverrides) {
  Scene scene = load_scene(scene_path("free_coast"));
  scene.duration = 1e17;
  EXPECT_THROW(Simulation{scene}, TimeLimitError);
}

TEST(StepSchedule, ClockRangeCheckForRosTime) {
  constexpr double kRosTimeLatest = 4294967295.0;  // ros::Time: 32-bit seconds [s]
  EXPECT_NO_THROW(check_times_within(0.0, 60.0, 0.0, kRosTimeLatest, "ROS time"));
  try {
    check_times_within(4294967296.0, 4294967297.0, 0.0, kRosTimeLatest, "ROS time");
    FAIL() << "2^32 s accepted";
  } catch (const TimeLimitError& error) {
    EXPECT_EQ(error.key(), "initial_state.time");
    EXPECT_NE(std::string(error.what()).find("ROS time"), std::string::npos);
  }
  try {
    check_times_within(4294967290.0, 4294967300.0, 0.0, kRosTimeLatest, "ROS time");
    FAIL() << "an end past 2^32 s accepted";
  } catch (const TimeLimitError& error) {
    EXPECT_EQ(error.key(), "duration");
  }
  EXPECT_THROW(check_times_within(-1.0, 1.0, 0.0, kRosTimeLatest, "ROS time"), TimeLimitError);
}

TEST(StepSchedule, StepsPerIntervalIsRangeChecked) {
  EXPECT_EQ(steps_per_interval(0.01, 1e-3), 10u);
  EXPECT_THROW(steps_per_interval(0.01, 3e-3), std::invalid_argument);       // not whole
  EXPECT_THROW(steps_per_interval(1e300, 1e-3), std::invalid_argument);      // 1e303 steps: beyond 2^53
  EXPECT_THROW(steps_per_interval(1e-4, 1e-3), std::invalid_argument);       // shorter than one step
  EXPECT_THROW(steps_per_interval(INFINITY, 1e-3), std::invalid_argument);
}

}  // namespace
}  // namespace birkhoff_cart
