// rostest node_bag: cart_sim's bag is written, complete, compressed, readable with the rosbag C++
// API and `rosbag info`, and holds the expected topics and counts; a cart_sim interrupted by SIGINT
// still leaves a complete bag; an unwritable ~bag_path stops cart_sim at once with an error.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <std_msgs/Float64.h>

#include "birkhoff_cart/IntegrationError.h"
#include "test_helpers.h"

namespace {

constexpr double kWaitTimeout = 60.0;  // [s of wall time], only against hangs

using birkhoff_cart_test::cart_sim_executable;
using birkhoff_cart_test::file_exists;
using birkhoff_cart_test::run_command;
using birkhoff_cart_test::start_cart_sim;
using birkhoff_cart_test::wait_exit;

std::map<std::string, int> count_topics(const std::string& path) {
  rosbag::Bag bag(path, rosbag::bagmode::Read);
  rosbag::View view(bag);
  std::map<std::string, int> counts;
  for (const rosbag::MessageInstance& message : view) ++counts[message.getTopic()];
  return counts;
}

TEST(NodeBag, RecordHasTopicsCountsAndCompression) {
  ros::NodeHandle node;
  std::string bag_path;
  double duration = 0.0, publish_rate = 0.0;
  ASSERT_TRUE(node.getParam("/cart_sim/bag_path", bag_path));
  ASSERT_TRUE(node.getParam("/cart_sim/duration", duration));
  ASSERT_TRUE(node.getParam("/cart_sim/publish_rate", publish_rate));
  ros::Publisher steering = node.advertise<std_msgs::Float64>("steering_torque", 10);
  ASSERT_TRUE(birkhoff_cart_test::wait_for([&] { return steering.getNumSubscribers() > 0; }, kWaitTimeout));
  // While paused the node is already recording; three commands go into the bag.
  for (double torque : {0.5, 1.0, 1.5}) {
    std_msgs::Float64 message;
    message.data = torque;
    steering.publish(message);
  }
  ros::WallDuration(0.5).sleep();  // delivery of the three commands before the run starts
  ASSERT_TRUE(birkhoff_cart_test::set_paused("/cart_sim/pause", false));

  // The bag appears under its final name only once it is closed.
  ASSERT_TRUE(birkhoff_cart_test::wait_for([&] { return file_exists(bag_path); }, kWaitTimeout)) << bag_path;
  EXPECT_FALSE(file_exists(bag_path + ".active"));

  const int expected = static_cast<int>(std::lround(duration * publish_rate));
  std::map<std::string, int> counts;
  ASSERT_NO_THROW(counts = count_topics(bag_path));
  EXPECT_EQ(counts["/cart_sim/integration_error"], expected);
  EXPECT_EQ(counts["/odom"], expected);
  EXPECT_EQ(counts["/joint_states"], expected);
  EXPECT_EQ(counts["/tf"], expected) << "odom -> base_link, so a replay in rviz places the cart";
  EXPECT_EQ(counts["/steering_torque"], 3);
  EXPECT_EQ(counts["/tf_static"], 1) << "map -> odom, once per bag";
  EXPECT_EQ(counts.count("/ground_truth"), 0u) << "without an odometry sensor odom is the ground truth";
  EXPECT_EQ(counts.size(), 6u);

  // Integration errors are stamped with scene time and carry the run's settings.
  rosbag::Bag bag(bag_path, rosbag::bagmode::Read);
  rosbag::View view(bag, rosbag::TopicQuery(std::vector<std::string>{"/cart_sim/integration_error"}));
  double previous = 0.0;
  int index = 0;
  for (const rosbag::MessageInstance& instance : view) {
    const auto error = instance.instantiate<birkhoff_cart::IntegrationError>();
    ASSERT_TRUE(error);
    ++index;
    EXPECT_NEAR(error->header.stamp.toSec(), index / publish_rate, 1e-9);
    EXPECT_EQ(instance.getTime(), error->header.stamp);
    EXPECT_GT(error->header.stamp.toSec(), previous);
    previous = error->header.stamp.toSec();
    EXPECT_EQ(error->integrator, "birkhoff2");
    EXPECT_FALSE(error->has_reference);
    EXPECT_GT(error->energy, 0.0);
  }
  bag.close();

  // `rosbag info` (python rosbag) reads it, and it is LZ4-compressed.
  std::string info;
  run_command("rosbag info --yaml " + bag_path, &info);
  EXPECT_NE(info.find("compression: lz4"), std::string::npos) << info;
  EXPECT_NE(info.find("/odom"), std::string::npos) << info;
  std::remove(bag_path.c_str());
}

TEST(NodeBag, SigintClosesTheBagCleanly) {
  ros::NodeHandle private_node("~");
  std::string scene;
  ASSERT_TRUE(private_node.getParam("scene", scene));
  const std::string bag_path = "/tmp/node_bag_sigint_" + std::to_string(::getpid()) + ".bag";
  // Real-time mode, unlimited duration, its own name and no /clock (the launched node owns it).
  const pid_t pid = start_cart_sim({"__name:=sigint_sim", "_scene:=" + scene, "_bag_path:=" + bag_path,
                                    "_fast:=false", "_duration:=0.0", "_publish_clock:=false",
                                    "_publish_tf:=false", "odom:=sigint/odom", "joint_states:=sigint/joint_states"});
  ASSERT_GT(pid, 0);
  ASSERT_TRUE(birkhoff_cart_test::wait_for([&] { return file_exists(bag_path + ".active"); }, kWaitTimeout));
  // 0.5 s of scene time gets recorded: waited for on the child's own odometry, not the wall clock.
  ros::NodeHandle node;
  int odom_count = 0;
  ros::Subscriber odom = node.subscribe<nav_msgs::Odometry>(
      "sigint/odom", 100, [&odom_count](const nav_msgs::Odometry::ConstPtr&) { ++odom_count; });
  ASSERT_TRUE(birkhoff_cart_test::wait_for([&] { return odom_count >= 50; }, kWaitTimeout)) << odom_count;
  ASSERT_EQ(::kill(pid, SIGINT), 0);
  EXPECT_EQ(wait_exit(pid, 30.0), 0);
  ASSERT_TRUE(file_exists(bag_path));
  EXPECT_FALSE(file_exists(bag_path + ".active"));
  std::map<std::string, int> counts;
  ASSERT_NO_THROW(counts = count_topics(bag_path));
  EXPECT_GE(counts["/sigint/odom"], odom_count);  // every instant heard before SIGINT is in the bag
  EXPECT_EQ(counts["/sigint/odom"], counts["/sigint/joint_states"]);
  std::remove(bag_path.c_str());
}

TEST(NodeBag, UnwritableBagPathStopsTheNode) {
  ros::NodeHandle private_node("~");
  std::string scene;
  ASSERT_TRUE(private_node.getParam("scene", scene));
  const pid_t pid = start_cart_sim({"__name:=unwritable_sim", "_scene:=" + scene,
                                    "_bag_path:=/nonexistent_directory/cart.bag", "_publish_clock:=false"});
  ASSERT_GT(pid, 0);
  const int status = wait_exit(pid, 30.0);
  EXPECT_NE(status, 0);
  EXPECT_NE(status, -1) << "cart_sim kept running without its record";
  EXPECT_NE(status, 127) << "could not start " << cart_sim_executable();
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "node_bag_test");
  ros::NodeHandle node;
  return RUN_ALL_TESTS();
}
