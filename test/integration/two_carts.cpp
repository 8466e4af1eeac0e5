// rostest two_carts: two cart_sim nodes under one master, in namespaces cart1 and cart2 with frame
// prefixes cart1/ and cart2/, and one /clock (cart1's; cart2's cart_sim follows it). For each cart:
// odom, joint_states and the tf tree (cartN/odom → cartN/base_link from cart_sim, the links from its
// robot_state_publisher) carry its own prefix, and its odometry agrees with a core Simulation of its
// own scene at every stamp; the two trees share no frame; /clock has one publisher and never goes
// back. The follower reset alone starts its scene again at the leader's current time (no stamp sent
// twice); reset with the leader (either first), its new run starts on the leader's new clock at once.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Clock.h>
#include <sensor_msgs/JointState.h>
#include <std_srvs/Empty.h>
#include <tf2/utils.h>
#include <tf2_ros/transform_listener.h>

#include "birkhoff_cart/core/scene/scene.h"
#include "birkhoff_cart/core/run/simulation.h"
#include "birkhoff_cart/ros/conversions.h"
#include "test_helpers.h"

namespace {

constexpr double kPositionTolerance = 1e-9;  // [m]
constexpr double kAngleTolerance = 1e-9;     // [rad]
constexpr double kStampTolerance = 1e-9;     // [s]
constexpr double kWaitTimeout = 60.0;        // [s of wall time], only against hangs
constexpr double kDuration = 2.0;            // the span checked, from both carts' start [s]
constexpr double kPublishRate = 50.0;        // both carts' ~publish_rate [Hz]
constexpr double kResetAfter = 8.0;          // scene time cart2 reaches before it is reset alone [s]

/// What one cart publishes, collected by topic.
struct CartRecord {
  std::string name;  // cart1, cart2
  std::vector<nav_msgs::Odometry> odometry;
  std::vector<sensor_msgs::JointState> joints;
  ros::Subscriber odometry_subscriber;
  ros::Subscriber joint_subscriber;
};

void listen(ros::NodeHandle& node, CartRecord& cart) {
  cart.odometry_subscriber = node.subscribe<nav_msgs::Odometry>(
      "/" + cart.name + "/odom", 1000, [&cart](const nav_msgs::Odometry::ConstPtr& m) { cart.odometry.push_back(*m); });
  cart.joint_subscriber = node.subscribe<sensor_msgs::JointState>(
      "/" + cart.name + "/joint_states", 1000,
      [&cart](const sensor_msgs::JointState::ConstPtr& m) { cart.joints.push_back(*m); });
}

void check_cart(const CartRecord& cart, const std::string& scene_path, const tf2_ros::Buffer& buffer) {
  SCOPED_TRACE(cart.name);
  const std::string prefix = cart.name + "/";
  const std::size_t expected = static_cast<std::size_t>(std::llround(kDuration * kPublishRate));
  ASSERT_GE(cart.odometry.size(), expected);
  ASSERT_GE(cart.joints.size(), expected);
  birkhoff_cart::Simulation simulation(birkhoff_cart::load_scene(scene_path));
  const double start_time = simulation.state().time;
  for (std::size_t k = 0; k < expected; ++k) {
    const nav_msgs::Odometry& odom = cart.odometry[k];
    const double stamp = odom.header.stamp.toSec();
    SCOPED_TRACE("instant " + std::to_string(k) + " at t = " + std::to_string(stamp));
    EXPECT_NEAR(stamp, start_time + static_cast<double>(k + 1) / kPublishRate, kStampTolerance);
    EXPECT_EQ(odom.header.frame_id, prefix + "odom");
    EXPECT_EQ(odom.child_frame_id, prefix + "base_link");
    simulation.advance_to(stamp);
    const Eigen::Vector2d rear_axle_midpoint = simulation.model().rear_axle_midpoint(simulation.state());
    EXPECT_NEAR(odom.pose.pose.position.x, rear_axle_midpoint.x(), kPositionTolerance);
    EXPECT_NEAR(odom.pose.pose.position.y, rear_axle_midpoint.y(), kPositionTolerance);
    EXPECT_NEAR(std::remainder(tf2::getYaw(odom.pose.pose.orientation) - simulation.state().heading, 2.0 * M_PI), 0.0,
                kAngleTolerance);
    // cart_sim's own transform, found under the cart's prefix at this stamp
    geometry_msgs::TransformStamped transform;
    ASSERT_NO_THROW(transform = buffer.lookupTransform(prefix + "odom", prefix + "base_link", odom.header.stamp));
    EXPECT_NEAR(transform.transform.translation.x, odom.pose.pose.position.x, kPositionTolerance);
    EXPECT_NEAR(transform.transform.translation.y, odom.pose.pose.position.y, kPositionTolerance);
  }
  const auto& names = birkhoff_cart::ros_conversions::joint_names();
  ASSERT_EQ(cart.joints[expected - 1].name.size(), names.size());
  for (std::size_t j = 0; j < names.size(); ++j) EXPECT_EQ(cart.joints[expected - 1].name[j], prefix + names[j]);
  // The whole tree: robot_state_publisher (fed the prefixed URDF and these joint_states) hangs the
  // links under cartN/base_link, so a wheel resolves in cartN/odom.
  const ros::Time last = cart.odometry[expected - 1].header.stamp;
  std::string error;
  for (const char* link : {"rear_body", "front_axle", "front_left_wheel", "rear_right_wheel"}) {
    EXPECT_TRUE(buffer.canTransform(prefix + "odom", prefix + link, last, &error)) << link << ": " << error;
  }
}

TEST(TwoCarts, EachCartHasItsOwnTreeAndOdometryUnderOneClock) {
  ros::NodeHandle node;
  ros::NodeHandle private_node("~");
  std::string cart1_scene, cart2_scene;
  ASSERT_TRUE(private_node.getParam("cart1_scene", cart1_scene));
  ASSERT_TRUE(private_node.getParam("cart2_scene", cart2_scene));
  CartRecord cart1{"cart1"}, cart2{"cart2"};
  listen(node, cart1);
  listen(node, cart2);
  std::vector<ros::Time> clocks;
  auto clock_subscriber = node.subscribe<rosgraph_msgs::Clock>(
      "/clock", 1000, [&](const rosgraph_msgs::Clock::ConstPtr& m) { clocks.push_back(m->clock); });
  tf2_ros::Buffer buffer(ros::Duration(60.0));
  tf2_ros::TransformListener listener(buffer);

  ASSERT_TRUE(birkhoff_cart_test::wait_for(
      [&] {
        return cart1.odometry_subscriber.getNumPublishers() > 0 && cart2.odometry_subscriber.getNumPublishers() > 0 &&
               clock_subscriber.getNumPublishers() > 0;
      },
      kWaitTimeout));
  ros::WallDuration(0.5).sleep();  // a second /clock publisher, if any, would have connected by now
  ros::spinOnce();
  EXPECT_EQ(clock_subscriber.getNumPublishers(), 1u) << "one node drives /clock";
  // cart2 first: it waits for a /clock that only cart1 publishes.
  ASSERT_TRUE(birkhoff_cart_test::set_paused("/cart2/cart_sim/pause", false));
  ASSERT_TRUE(birkhoff_cart_test::set_paused("/cart1/cart_sim/pause", false));
  const std::size_t expected = static_cast<std::size_t>(std::llround(kDuration * kPublishRate));
  ASSERT_TRUE(birkhoff_cart_test::wait_for(
      [&] { return cart1.odometry.size() >= expected && cart2.odometry.size() >= expected; }, kWaitTimeout))
      << cart1.odometry.size() << " and " << cart2.odometry.size() << " odom of " << expected;
  ASSERT_TRUE(birkhoff_cart_test::wait_for(
      [&] { return cart1.joints.size() >= expected && cart2.joints.size() >= expected; }, kWaitTimeout));
  // The robot_state_publishers' transforms of the last checked instant: the carts run on, so
  // wait until a later instant has come from both.
  ASSERT_TRUE(birkhoff_cart_test::wait_for(
      [&] { return cart1.odometry.size() >= expected + 10 && cart2.odometry.size() >= expected + 10; }, kWaitTimeout));

  ASSERT_FALSE(clocks.empty());
  for (std::size_t i = 1; i < clocks.size(); ++i) EXPECT_GT(clocks[i], clocks[i - 1]) << "/clock went back";

  check_cart(cart1, cart1_scene, buffer);
  check_cart(cart2, cart2_scene, buffer);
  // Two trees joined only at the shared world frame `map` (each cart_sim: the identity map → cartN/odom).
  ASSERT_TRUE(buffer.canTransform("cart1/odom", "cart2/odom", ros::Time(0)));
  const geometry_msgs::TransformStamped between = buffer.lookupTransform("cart1/odom", "cart2/odom", ros::Time(0));
  EXPECT_EQ(between.transform.translation.x, 0.0);
  EXPECT_EQ(between.transform.rotation.w, 1.0);
  EXPECT_FALSE(buffer._frameExists("odom")) << "an unprefixed frame leaked";
  EXPECT_FALSE(buffer._frameExists("base_link")) << "an unprefixed frame leaked";
  // The carts really moved apart from rest.
  EXPECT_GT(std::abs(cart2.odometry[expected - 1].pose.pose.position.x - cart2.odometry.front().pose.pose.position.x),
            1.0);

  // The follower alone reset: its scene starts again at the leader's current time, on
  // its publish grid, and goes on from there. Before, it replayed the leader's past in a burst
  // (stamps from t0 again: TF_REPEATED_DATA in every tf listener).
  ASSERT_TRUE(birkhoff_cart_test::wait_for(
      [&] { return cart2.odometry.back().header.stamp.toSec() >= kResetAfter; }, kWaitTimeout));
  std_srvs::Empty reset;
  const std::size_t before_call = cart2.odometry.size();
  ASSERT_TRUE(ros::service::call("/cart2/cart_sim/reset", reset));
  // Odometry of the old run that was still in the subscriber's queue when the call returned arrives
  // after it (a loaded machine: a clean-clone run saw one message): the new run begins at the first
  // message at the scene's pose one publish interval after its start.
  const Eigen::Vector2d first_pose = [&] {
    birkhoff_cart::Simulation probe(birkhoff_cart::load_scene(cart2_scene));
    probe.advance_to(probe.scene().initial_state.time + 1.0 / kPublishRate);
    return probe.model().rear_axle_midpoint(probe.state());
  }();
  std::size_t before_follower_reset = before_call;  // the new run's first message
  ASSERT_TRUE(birkhoff_cart_test::wait_for(
      [&] {
        while (before_follower_reset < cart2.odometry.size() &&
               std::hypot(cart2.odometry[before_follower_reset].pose.pose.position.x - first_pose.x(),
                          cart2.odometry[before_follower_reset].pose.pose.position.y - first_pose.y()) > kPositionTolerance) {
          ++before_follower_reset;
        }
        return cart2.odometry.size() >= before_follower_reset + expected;
      },
      kWaitTimeout))
      << "cart2's new run never started at its scene's first pose";
  EXPECT_LE(before_follower_reset - before_call, 10u) << "messages of the old run after the ~reset call returned";
  for (std::size_t i = before_follower_reset; i < before_follower_reset + expected; ++i) {
    EXPECT_GT(cart2.odometry[i].header.stamp, cart2.odometry[i - 1].header.stamp)
        << "cart2 sent a stamp again after its ~reset: " << cart2.odometry[i].header.stamp.toSec() << " s";
  }
  {
    // The new run is the scene's run shifted to its new start (free_coast has no time-dependent load).
    const double new_start = cart2.odometry[before_follower_reset].header.stamp.toSec() - 1.0 / kPublishRate;
    EXPECT_GE(new_start, kResetAfter - kStampTolerance) << "cart2 started again in the leader's past";
    birkhoff_cart::Simulation simulation(birkhoff_cart::load_scene(cart2_scene));
    for (std::size_t i = before_follower_reset; i < before_follower_reset + expected; ++i) {
      const nav_msgs::Odometry& odom = cart2.odometry[i];
      SCOPED_TRACE("after cart2's reset, at t = " + std::to_string(odom.header.stamp.toSec()));
      simulation.advance_to(simulation.scene().initial_state.time + (odom.header.stamp.toSec() - new_start));
      const Eigen::Vector2d rear_axle_midpoint = simulation.model().rear_axle_midpoint(simulation.state());
      EXPECT_NEAR(odom.pose.pose.position.x, rear_axle_midpoint.x(), kPositionTolerance);
      EXPECT_NEAR(odom.pose.pose.position.y, rear_axle_midpoint.y(), kPositionTolerance);
    }
  }

  // Then the follower and the leader reset, in either order: the follower's new run starts on the
  // leader's new clock at once. Before, with the follower reset first, it then waited, frozen and
  // without a log line, until the leader's clock came back to its time.
  for (const bool leader_first : {false, true}) {
    SCOPED_TRACE(leader_first ? "the leader reset first" : "the follower reset first");
    const double after = cart2.odometry.back().header.stamp.toSec() + 1.0;  // [s]
    ASSERT_TRUE(birkhoff_cart_test::wait_for(
        [&] { return cart2.odometry.back().header.stamp.toSec() >= after; }, kWaitTimeout));
    const double before_reset = cart2.odometry.back().header.stamp.toSec();  // [s]
    const std::size_t clocks_before_reset = clocks.size();
    ASSERT_TRUE(ros::service::call(leader_first ? "/cart1/cart_sim/reset" : "/cart2/cart_sim/reset", reset));
    ASSERT_TRUE(ros::service::call(leader_first ? "/cart2/cart_sim/reset" : "/cart1/cart_sim/reset", reset));
    // /clock messages of the leader's new run that came before the follower's first new odom: a
    // handful when the follower starts at once; about before_reset × 50 Hz when it waits for /clock
    // to come back to its pre-reset time.
    std::size_t new_clocks_first = 0;
    ASSERT_TRUE(birkhoff_cart_test::wait_for(
        [&] {
          if (cart2.odometry.back().header.stamp.toSec() >= 0.5 * before_reset) return false;
          for (std::size_t i = clocks_before_reset; i < clocks.size(); ++i) {
            new_clocks_first += clocks[i].toSec() < 0.5 * before_reset ? 1 : 0;
          }
          return true;
        },
        kWaitTimeout))
        << "cart2 published nothing of its new run: " << cart2.odometry.size() << " odom, the last at "
        << cart2.odometry.back().header.stamp.toSec() << " s; /clock at " << clocks.back().toSec() << " s";
    EXPECT_LT(new_clocks_first, 50u) << "cart2 resumed only after " << new_clocks_first
                                     << " /clock messages of the new run (reset at " << before_reset << " s)";
  }
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "two_carts_test");
  ros::NodeHandle node;
  return RUN_ALL_TESTS();
}
