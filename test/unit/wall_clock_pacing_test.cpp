// WallClockPacing (real-time deadlines), ROS-free.
#include <gtest/gtest.h>

#include <chrono>

#include "birkhoff_cart/core/node_logic/wall_clock_pacing.h"

namespace birkhoff_cart {
namespace {

using Clock = WallClockPacing::Clock;
using std::chrono::duration;
using std::chrono::duration_cast;

constexpr double kTimeTolerance = 1e-9;  // [s]; durations go through integer nanoseconds

Clock::time_point at(double seconds) { return Clock::time_point(duration_cast<Clock::duration>(duration<double>(seconds))); }
double seconds(Clock::time_point wall) { return duration<double>(wall.time_since_epoch()).count(); }

TEST(WallClockPacing, SceneTimeIsDueAtAnchorPlusElapsedOverFactor) {
  WallClockPacing pacing(2.0);  // twice real time
  pacing.restart(at(100.0), 5.0);
  EXPECT_NEAR(seconds(pacing.due(5.0)), 100.0, kTimeTolerance);
  EXPECT_NEAR(seconds(pacing.due(7.0)), 101.0, kTimeTolerance);
  EXPECT_NEAR(pacing.scene_time_at(at(103.0)), 11.0, kTimeTolerance);
  EXPECT_TRUE(pacing.paced());
  EXPECT_FALSE(WallClockPacing(0.0).paced());
}

TEST(WallClockPacing, ResetDeadlinesFollowTheNewAnchor) {
  // Regression: ~reset in real-time mode kept the deadline of the old run: after 5 s of running,
  // the first step of the new run was due 5 s late (/clock stalled), then the node fast-forwarded.
  WallClockPacing pacing(1.0);
  pacing.restart(at(0.0), 0.0);
  const double step = 1e-3;  // [s]
  EXPECT_NEAR(seconds(pacing.due(5.0)), 5.0, kTimeTolerance);
  pacing.restart(at(5.0), 0.0);  // reset at wall 5 s: scene time back to 0
  EXPECT_NEAR(seconds(pacing.due(step)), 5.0 + step, kTimeTolerance);
  EXPECT_NEAR(pacing.scene_time_at(at(5.5)), 0.5, kTimeTolerance);
}

TEST(WallClockPacing, ATinyFactorPutsTheDueInstantFarAwayNotIntoOverflow) {
  // Regression: ~real_time_factor 1e-300 made (t - t_anchor) / factor 1e298 s, whose conversion to
  // int64 nanoseconds overflowed (undefined; the deadline came out in the past or anywhere).
  WallClockPacing pacing(1e-300);
  pacing.restart(at(100.0), 5.0);
  EXPECT_NEAR(seconds(pacing.due(5.001)), 100.0 + WallClockPacing::kFarthestDue, 1e-3);
  EXPECT_GT(pacing.due(5.001), pacing.due(5.0));
}

TEST(WallClockPacing, PauseDoesNotAccumulateADebt) {
  WallClockPacing pacing(1.0);
  pacing.restart(at(0.0), 0.0);
  // Paused at scene time 2 s from wall 2 s to wall 12 s: restarted at the end of the pause.
  pacing.restart(at(12.0), 2.0);
  EXPECT_NEAR(pacing.scene_time_at(at(12.5)), 2.5, kTimeTolerance);  // not 12.5: no burst after a pause
}

}  // namespace
}  // namespace birkhoff_cart
