// BagRecorder's ring and writer thread: more messages than the ring holds, written as fast as the
// loop can (the full-ring wait and the batched wake-up of the writer), all reach the bag in order;
// fewer than one wake-up batch are written at close(); a bag already at the path is kept under
// its modification time, never overwritten. No master needed; files in a scratch
// directory removed at the end.
#include <gtest/gtest.h>

#include <stdlib.h>
#include <unistd.h>

#include <cstdio>
#include <string>
#include <vector>

#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <std_msgs/Float64.h>

#include "birkhoff_cart/ros/bag_recorder.h"

namespace birkhoff_cart {
namespace {

/// Writes `count` commands at t = k ms through a recorder, closes it and reads the bag back.
void record_and_check(std::size_t count) {
  char pattern[] = "/tmp/bag_recorder_test.XXXXXX";
  const char* directory = ::mkdtemp(pattern);
  ASSERT_NE(directory, nullptr);
  const std::string path = std::string(directory) + "/ring.bag";
  {
    BagRecorder recorder(path, BagRecorder::Compression::kLz4);
    std_msgs::Float64 command;
    for (std::size_t k = 1; k <= count; ++k) {
      command.data = static_cast<double>(k);
      recorder.write("/steering_torque", ros::Time(1e-3 * static_cast<double>(k)), command);
    }
    recorder.close();
    EXPECT_EQ(recorder.message_counts().at("/steering_torque"), count);
  }
  {
    rosbag::Bag bag(path, rosbag::bagmode::Read);
    rosbag::View view(bag);
    EXPECT_EQ(view.size(), count);
    std::size_t k = 0;
    for (const rosbag::MessageInstance& instance : view) {
      ++k;
      const std_msgs::Float64::ConstPtr command = instance.instantiate<std_msgs::Float64>();
      ASSERT_TRUE(command != nullptr);
      EXPECT_EQ(command->data, static_cast<double>(k)) << "message " << k << " out of order or lost";
    }
  }
  std::remove(path.c_str());
  ::rmdir(directory);
}

TEST(BagRecorder, MoreMessagesThanTheRingHoldsAllReachTheBagInOrder) {
  record_and_check(20 * BagRecorder::kQueueCapacity + 7);
}

TEST(BagRecorder, FewerMessagesThanOneWakeUpBatchAreWrittenAtClose) {
  record_and_check(BagRecorder::kWakeBatch / 2);
}

TEST(BagRecorder, AnEarlierBagAtThePathIsKeptUnderItsTime) {
  char pattern[] = "/tmp/bag_recorder_test.XXXXXX";
  const char* directory = ::mkdtemp(pattern);
  ASSERT_NE(directory, nullptr);
  const std::string path = std::string(directory) + "/run.bag";
  std::FILE* earlier = std::fopen(path.c_str(), "w");
  ASSERT_NE(earlier, nullptr);
  std::fputs("the earlier run", earlier);
  std::fclose(earlier);
  const std::string kept = kept_path_for(path);
  EXPECT_EQ(kept.rfind(std::string(directory) + "/run_2", 0), 0u) << kept;  // run_<YYYYMMDD-HHMMSS>.bag
  EXPECT_EQ(kept.size(), path.size() + 16) << kept;
  {
    BagRecorder recorder(path, BagRecorder::Compression::kNone);
    EXPECT_EQ(recorder.earlier_bag_kept_as(), kept);
    std_msgs::Float64 command;
    command.data = 1.0;
    recorder.write("/steering_torque", ros::Time(1.0), command);
    recorder.close();
  }
  std::FILE* moved = std::fopen(kept.c_str(), "r");
  ASSERT_NE(moved, nullptr) << "the earlier bag is gone";
  char text[32] = {};
  EXPECT_NE(std::fgets(text, sizeof text, moved), nullptr);
  std::fclose(moved);
  EXPECT_STREQ(text, "the earlier run");
  {
    rosbag::Bag bag(path, rosbag::bagmode::Read);
    EXPECT_EQ(rosbag::View(bag).size(), 1u);
  }
  // A second earlier bag with the same time stamp gets "-2".
  std::FILE* again = std::fopen(kept.c_str(), "r");
  ASSERT_NE(again, nullptr);
  std::fclose(again);
  std::string second;
  {
    BagRecorder recorder(path, BagRecorder::Compression::kNone);
    second = recorder.earlier_bag_kept_as();
    recorder.close();
  }
  EXPECT_FALSE(second.empty());
  EXPECT_NE(second, kept);
  for (const std::string& file : {path, kept, second}) std::remove(file.c_str());
  ::rmdir(directory);
}

}  // namespace
}  // namespace birkhoff_cart
