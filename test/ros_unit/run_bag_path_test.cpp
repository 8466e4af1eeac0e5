// run_bag_path (one bag per run), and RunRecord's runs of a node whose path another node holds,
// without a master.
#include <gtest/gtest.h>

#include <stdlib.h>
#include <unistd.h>

#include <cstdlib>
#include <string>

#include "birkhoff_cart/ros/bag_recorder.h"
#include "birkhoff_cart/ros/run_record.h"

namespace birkhoff_cart {
namespace {

TEST(RunBagPath, FirstRunKeepsThePathLaterRunsAreNumbered) {
  EXPECT_EQ(run_bag_path("/data/drive.bag", 1), "/data/drive.bag");
  EXPECT_EQ(run_bag_path("/data/drive.bag", 2), "/data/drive_run2.bag");
  EXPECT_EQ(run_bag_path("/data/drive.bag", 12), "/data/drive_run12.bag");
  EXPECT_EQ(run_bag_path("record", 3), "record_run3");
  EXPECT_EQ(run_bag_path(".bag", 2), ".bag_run2");
}

TEST(RunRecord, ANodeWhosePathIsTakenKeepsItsRunsBesideItsOwnBag) {
  char pattern[] = "/tmp/run_bag_path_test.XXXXXX";
  const char* directory = ::mkdtemp(pattern);
  ASSERT_NE(directory, nullptr);
  const std::string path = std::string(directory) + "/drive.bag";
  const std::string own = std::string(directory) + "/drive_pid" + std::to_string(::getpid());
  {
    RunRecord first(path, "lz4", 0);
    RunRecord second(path, "lz4", 0);
    EXPECT_EQ(second.bag().path(), own + ".bag");
    second.next_run();  // ~reset
    EXPECT_EQ(second.bag().path(), own + "_run2.bag");
    first.next_run();
    EXPECT_EQ(first.bag().path(), std::string(directory) + "/drive_run2.bag");
    EXPECT_FALSE(first.failure() || second.failure());
    first.finish();
    second.finish();
  }
  for (const std::string& bag : {path, std::string(directory) + "/drive_run2.bag", own + ".bag", own + "_run2.bag"}) {
    EXPECT_EQ(::access(bag.c_str(), F_OK), 0) << bag;
  }
  std::system(("rm -rf " + std::string(directory)).c_str());
}

}  // namespace
}  // namespace birkhoff_cart
