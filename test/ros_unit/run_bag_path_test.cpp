// run_bag_path (one bag per run), without a master.
#include <gtest/gtest.h>

#include "birkhoff_cart/ros/bag_recorder.h"

namespace birkhoff_cart {
namespace {

TEST(RunBagPath, FirstRunKeepsThePathLaterRunsAreNumbered) {
  EXPECT_EQ(run_bag_path("/data/drive.bag", 1), "/data/drive.bag");
  EXPECT_EQ(run_bag_path("/data/drive.bag", 2), "/data/drive_run2.bag");
  EXPECT_EQ(run_bag_path("/data/drive.bag", 12), "/data/drive_run12.bag");
  EXPECT_EQ(run_bag_path("record", 3), "record_run3");
  EXPECT_EQ(run_bag_path(".bag", 2), ".bag_run2");
}

}  // namespace
}  // namespace birkhoff_cart
