// BagRecorder's ring and writer thread: more messages than the ring holds, written as fast as the
// loop can (the full-ring wait and the batched wake-up of the writer), all reach the bag in order;
// fewer than one wake-up batch are written at close(). No master needed; files in a scratch
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

}  // namespace
}  // namespace birkhoff_cart
