// RunWorkMeter (run_work_meter.h): what a run costs in wall time, on a made-up clock.
#include <gtest/gtest.h>

#include <chrono>

#include "birkhoff_cart/core/node_logic/run_work_meter.h"

namespace birkhoff_cart {
namespace {

using Clock = RunWorkMeter::Clock;

Clock::time_point at(double seconds) {
  return Clock::time_point(std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds)));
}

TEST(RunWorkMeter, RealTimeFactorIsSceneTimeOverWallTimeNotPaused) {
  RunWorkMeter meter;
  meter.start(at(100.0), 5.0);
  EXPECT_EQ(meter.real_time_factor(at(100.0)), 0.0);  // no wall time yet
  for (int k = 0; k < 400; ++k) meter.count_step(0.01);  // 4 s of scene time
  meter.add_paused(1.0);
  EXPECT_NEAR(meter.real_time_factor(at(103.0)), 4.0 / 2.0, 1e-12);  // 3 s of wall time, 1 s paused
  EXPECT_NEAR(meter.wall_time(at(103.0)), 3.0, 1e-9);
  EXPECT_EQ(meter.steps(), 400u);
  EXPECT_EQ(meter.paused_wall_time(), 1.0);
}

TEST(RunWorkMeter, WallTimePerStepIsThePeriodsMeanAndStartsAgainAtEachInstant) {
  RunWorkMeter meter;
  meter.start(at(0.0), 0.0);
  EXPECT_EQ(meter.end_period(), 0.0);  // no step: 0, not a division by zero
  for (int k = 0; k < 4; ++k) meter.count_step(0.001);
  meter.add_stepping(0.002);
  meter.add_stepping(0.006);
  EXPECT_DOUBLE_EQ(meter.end_period(), 0.002);
  meter.count_step(0.001);
  meter.add_stepping(0.0005);
  EXPECT_DOUBLE_EQ(meter.end_period(), 0.0005);
  EXPECT_DOUBLE_EQ(meter.last_wall_time_per_step(), 0.0005);
  EXPECT_EQ(meter.published_instants(), 3u);
  EXPECT_DOUBLE_EQ(meter.stepping_wall_time(), 0.0085);  // the whole run's stays
  EXPECT_EQ(meter.steps(), 5u);
}

TEST(RunWorkMeter, ProgressAtMostOncePerPeriodWithTheRateSinceTheLastLine) {
  RunWorkMeter meter;
  meter.start(at(10.0), 2.0);
  EXPECT_FALSE(meter.progress(at(10.5), 40.0));  // half a second: no line
  const std::optional<double> first = meter.progress(at(11.25), 52.0);
  ASSERT_TRUE(first);
  EXPECT_NEAR(*first, (52.0 - 2.0) / 1.25, 1e-9);
  EXPECT_FALSE(meter.progress(at(12.0), 60.0));
  const std::optional<double> second = meter.progress(at(13.25), 72.0);
  ASSERT_TRUE(second);
  EXPECT_NEAR(*second, 20.0 / 2.0, 1e-9);
}

}  // namespace
}  // namespace birkhoff_cart
