// RunTimeline (cart_sim's run length and the ROS-time rules), start_on_leader_clock and
// pacing_factor, ROS-free.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "birkhoff_cart/core/node_logic/run_timeline.h"

namespace birkhoff_cart {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();
constexpr double kStep = 1e-3;  // h [s]

/// The message of the RunTimelineError that `plan` throws ("" if none).
template <class Plan>
std::string refusal(Plan plan) {
  try {
    plan();
  } catch (const RunTimelineError& error) {
    return error.what();
  }
  return "";
}

TEST(RunTimeline, DurationParameterChoosesTheRunLength) {
  EXPECT_EQ(RunTimeline(-1.0, 60.0, kStep, "s.yaml", 0.0).duration(), 60.0);  // < 0: the scene's
  EXPECT_EQ(RunTimeline(-1.0, 60.0, kStep, "s.yaml", 0.0).end_time(), 60.0);
  EXPECT_EQ(RunTimeline(5.0, 60.0, kStep, "s.yaml", 2.0).end_time(), 7.0);    // > 0: its own
  EXPECT_EQ(RunTimeline(0.0, 60.0, kStep, "s.yaml", 0.0).duration(), kInfinity);  // 0: without end
  EXPECT_EQ(RunTimeline(0.0, 60.0, kStep, "s.yaml", 0.0).end_time(), kInfinity);
  EXPECT_EQ(RunTimeline(kInfinity, 60.0, kStep, "s.yaml", 0.0).end_time(), kInfinity);
}

TEST(RunTimeline, TheEndIsWhereTheStepRuleLandsIt) {
  // 4.6960000000005 s from t0 = 1 s: the step rule's end is t0 + T as a double (not rounded to the grid).
  const RunTimeline timeline(4.6960000000005, 60.0, kStep, "s.yaml", 1.0);
  EXPECT_EQ(timeline.end_time(), 1.0 + 4.6960000000005);
}

TEST(RunTimeline, WholeRunsAndTheRestOfARun) {
  const RunTimeline timeline(10.0, 60.0, kStep, "s.yaml", 2.0);
  EXPECT_EQ(timeline.length_from(2.0, true), 10.0);
  EXPECT_EQ(timeline.length_from(5.0, false), 7.0);  // after a teleport at 5 s: up to 12 s
  const RunTimeline endless(0.0, 60.0, kStep, "s.yaml", 2.0);
  EXPECT_EQ(endless.length_from(5.0, false), kInfinity);
}

TEST(RunTimeline, AWholeRunStartsAgainElsewhereWithItsLength) {
  RunTimeline timeline(10.0, 60.0, kStep, "s.yaml", 0.0);
  timeline.start_at(86.6);  // a follower on its leader's clock
  EXPECT_EQ(timeline.start_time(), 86.6);
  EXPECT_EQ(timeline.end_time(), 96.6);
}

TEST(RunTimeline, RefusesNegativeStartsByName) {
  EXPECT_NE(refusal([] { RunTimeline(-1.0, 60.0, kStep, "neg.yaml", -0.5); }).find(
                "scene neg.yaml starts at t = -0.5 s: cart_sim publishes scene time as ROS time, which must be >= 0"),
            std::string::npos);
  EXPECT_NE(refusal([] { RunTimeline(-1.0, 60.0, kStep, "nan.yaml", std::nan("")); }).find("starts at t = nan"),
            std::string::npos);
}

TEST(RunTimeline, RefusesRunsPastRosTimeAndLeavesTheRunAsItWas) {
  const std::string past = refusal([] { RunTimeline(-1.0, 10.0, 1.0, "late.yaml", kLatestRosTime - 5.0); });
  EXPECT_NE(past.find("which ends before 2^32 s = 4294967295 s"), std::string::npos) << past;
  EXPECT_NE(refusal([] { RunTimeline(0.0, 10.0, 1.0, "late.yaml", kLatestRosTime); }).find("2^32"),
            std::string::npos);
  RunTimeline timeline(10.0, 60.0, 1.0, "s.yaml", 0.0);
  EXPECT_THROW(timeline.start_at(kLatestRosTime - 5.0), RunTimelineError);
  EXPECT_EQ(timeline.start_time(), 0.0);
  EXPECT_EQ(timeline.end_time(), 10.0);
}

TEST(RunTimeline, NamesTheDurationParameterOrTheSceneKey) {
  // A duration of a hair (below the step rule's resolution at this start) from ~duration or the scene.
  const std::string from_parameter = refusal([] { RunTimeline(1e-300, 60.0, kStep, "s.yaml", 0.0); });
  EXPECT_NE(from_parameter.find("cannot be cut into steps: ~duration:"), std::string::npos) << from_parameter;
  const std::string from_scene = refusal([] { RunTimeline(-1.0, 1e9, 1e-9, "s.yaml", 0.0); });
  EXPECT_NE(from_scene.find("cannot be cut into steps: scene key '"), std::string::npos) << from_scene;
}

TEST(StartOnLeaderClock, TheLatestOwnInstantAtOrBeforeTheLeadersTime) {
  EXPECT_EQ(start_on_leader_clock(0.0, 0.0, 0.01), 0.0);    // the leader has not started
  EXPECT_EQ(start_on_leader_clock(0.0, 0.001, 0.01), 0.0);  // its first /clock (t0 + h): start at t0
  EXPECT_EQ(start_on_leader_clock(0.0, kLongestCatchUp, 0.01), 0.0);  // a lag the follower catches up
  EXPECT_NEAR(start_on_leader_clock(0.0, 86.6, 0.01), 86.6, 1e-12);  // on the grid: there (no round-off step back)
  EXPECT_NEAR(start_on_leader_clock(0.0, 86.613, 0.01), 86.61, 1e-12);
  EXPECT_NEAR(start_on_leader_clock(1.0, 3.05, 0.5), 3.0, 1e-12);
  EXPECT_EQ(start_on_leader_clock(5.0, 2.0, 0.01), 5.0);  // a leader behind the scene's start
  // After the follower's own ~reset: on the clock however little it is ahead (no stamp sent twice).
  EXPECT_NEAR(start_on_leader_clock(0.0, 0.061, 0.02, 0.0), 0.06, 1e-12);
  EXPECT_EQ(start_on_leader_clock(0.0, 0.0, 0.02, 0.0), 0.0);
}

TEST(PacingFactor, RealTimeFastAndFollowing) {
  EXPECT_EQ(pacing_factor(false, 0.0, false), 1.0);  // real time
  EXPECT_EQ(pacing_factor(false, 3.0, false), 3.0);
  EXPECT_EQ(pacing_factor(true, 0.0, false), 0.0);   // fast: unpaced
  EXPECT_EQ(pacing_factor(true, 4.0, false), 4.0);
  EXPECT_EQ(pacing_factor(false, 3.0, true), 0.0);   // the leader's /clock is the pace
}

}  // namespace
}  // namespace birkhoff_cart
