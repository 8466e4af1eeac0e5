// No allocation per step or per publish instant: the node's publishing path — steps of
// the default scene (its dopri5 shadow reference included), the messages of each instant filled
// in place (InstantMessages, with the accuracy guard's check) and written to the bag's ring
// (BagRecorder::write) — is run with a replaced global operator new that counts the allocations
// of this thread. After a warm-up (the messages hold their strings; every ring slot has held its
// message type once) the count over many instants must be zero. The bag's writer thread (chunk
// bookkeeping) and roscpp's publish (its typed publish() builds a std::string of the md5sum at
// every call, and serializes for a topic with subscribers) are outside this path and not counted. Also: filled messages
// (odometry, ground truth, joint states, the transform, integration_error) equal the to_* conversions. No master needed.
#include <gtest/gtest.h>

#include <stdlib.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <new>
#include <string>
#include <vector>

#include <ros/serialization.h>

#include "birkhoff_cart/core/scene/scene.h"
#include "birkhoff_cart/core/run/simulation.h"
#include "birkhoff_cart/ros/bag_recorder.h"
#include "birkhoff_cart/ros/instant_messages.h"

namespace {
thread_local bool counting = false;        // count this thread's allocations now
thread_local std::size_t allocations = 0;  // operator new calls counted
}  // namespace

// The replacements below pair malloc with free on purpose; GCC sees free() of a new-expression's
// pointer (inlined into the standard allocators) and warns.
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void* operator new(std::size_t size) {
  if (counting) ++allocations;
  if (void* memory = std::malloc(size == 0 ? 1 : size)) return memory;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size) { return operator new(size); }
void operator delete(void* memory) noexcept { std::free(memory); }
void operator delete[](void* memory) noexcept { std::free(memory); }
void operator delete(void* memory, std::size_t) noexcept { std::free(memory); }
void operator delete[](void* memory, std::size_t) noexcept { std::free(memory); }

namespace birkhoff_cart {
namespace {

constexpr int kStepsPerInstant = 10;      // h = 1 ms, 100 Hz publishing
constexpr int kWarmUpInstants = 400;      // > one lap of the ring: 4 messages × 400 > kQueueCapacity
constexpr int kCountedInstants = 2000;    // 20 s of scene time
constexpr char kPrefix[] = "a_fleet_of_carts/cart1/";

std::string default_scene_path() { return std::string(BIRKHOFF_CART_SOURCE_DIR) + "/config/scenes/default.yaml"; }

Scene stepping_scene() {
  Scene scene = load_scene(default_scene_path());
  scene.integrator.name = "birkhoff2";  // the node-cost benchmark's stepping (docs/benchmarks.md §7)
  scene.integrator.step_size = 1e-3;
  scene.duration = 1000.0;
  return scene;
}

// A prefix that puts every frame and joint name beyond the small-string buffer (15 chars).
ros_conversions::FrameNames prefixed() { return ros_conversions::prefixed_frames(kPrefix, "odom", "base_link"); }

/// The node's order at a publish instant: the guard judges the diagnostics, then the messages are
/// filled from them and from the guard (a fill changes nothing but the messages).
void check_and_fill(const Simulation& simulation, AccuracyGuard& guard, InstantMessages& messages,
                    double wall_time_per_step) {
  const Diagnostics diagnostics = simulation.diagnostics();
  guard.check(simulation.state().time, diagnostics, simulation.statistics());
  messages.fill(simulation, diagnostics, guard, wall_time_per_step);
}

/// One publish instant of the node: steps, guard check and fill, the four bag writes.
void run_instant(Simulation& simulation, InstantMessages& messages, AccuracyGuard& guard, BagRecorder& recorder,
                 const std::string& odometry_topic, const std::string& joint_state_topic,
                 const std::string& error_topic) {
  for (int k = 0; k < kStepsPerInstant; ++k) simulation.step();
  check_and_fill(simulation, guard, messages, 1e-6);
  recorder.write(error_topic, messages.integration_error.header.stamp, messages.integration_error);
  recorder.write(odometry_topic, messages.odometry.header.stamp, messages.odometry);
  recorder.write(joint_state_topic, messages.joints.header.stamp, messages.joints);
  recorder.write("/tf", messages.odometry.header.stamp, messages.transforms);
}

TEST(InstantMessages, NoAllocationPerStepOrPublishInstantAfterWarmUp) {
  char pattern[] = "/tmp/instant_messages_test.XXXXXX";
  const char* directory = ::mkdtemp(pattern);
  ASSERT_NE(directory, nullptr);
  const std::string bag_path = std::string(directory) + "/instants.bag";
  {
    Simulation simulation(stepping_scene());
    ASSERT_TRUE(simulation.diagnostics().has_reference) << "the default scene should carry its shadow reference";
    AccuracyGuard guard(simulation.scene().accuracy);
    InstantMessages messages(prefixed(), ros_conversions::OdometryCovariance{});
    BagRecorder recorder(bag_path, BagRecorder::Compression::kLz4);
    // Topic names longer than the small-string buffer, as the node's resolved names are.
    const std::string odometry_topic = "/a_namespace_of_some_length/odom";
    const std::string joint_state_topic = "/a_namespace_of_some_length/joint_states";
    const std::string error_topic = "/a_namespace_of_some_length/cart_sim/integration_error";
    for (int k = 0; k < kWarmUpInstants; ++k) {
      run_instant(simulation, messages, guard, recorder, odometry_topic, joint_state_topic, error_topic);
    }
    allocations = 0;
    counting = true;
    for (int k = 0; k < kCountedInstants; ++k) {
      run_instant(simulation, messages, guard, recorder, odometry_topic, joint_state_topic, error_topic);
    }
    counting = false;
    EXPECT_EQ(allocations, 0u) << "allocations in " << kCountedInstants << " publish instants of "
                               << kStepsPerInstant << " steps each";
    std::printf("[ measured ] %zu allocations in %d instants (%d steps)\n", allocations, kCountedInstants,
                kCountedInstants * kStepsPerInstant);
    recorder.close();
  }
  std::remove(bag_path.c_str());
  ::rmdir(directory);
}

template <class M>
std::vector<std::uint8_t> serialized(const M& message) {
  std::vector<std::uint8_t> bytes(ros::serialization::serializationLength(message));
  ros::serialization::OStream stream(bytes.data(), static_cast<std::uint32_t>(bytes.size()));
  ros::serialization::serialize(stream, message);
  return bytes;
}

TEST(InstantMessages, FilledMessagesEqualTheConversions) {
  Simulation simulation(stepping_scene());
  for (int k = 0; k < 137; ++k) simulation.step();
  AccuracyGuard guard(simulation.scene().accuracy);
  InstantMessages messages(prefixed(), ros_conversions::OdometryCovariance{});
  check_and_fill(simulation, guard, messages, 2e-6);
  for (int k = 0; k < 50; ++k) simulation.step();
  check_and_fill(simulation, guard, messages, 3e-6);  // a second fill overwrites every field
  const CartState& state = simulation.state();
  const nav_msgs::Odometry odometry = ros_conversions::to_odometry(state, simulation.model(), prefixed());
  EXPECT_EQ(messages.odometry, odometry);
  // The ground truth: the exact state in the world frame, on its own child frame (base_link is the
  // odometry's), covariances 0 (its pose and twist are odom's, copied rather than computed again).
  ros_conversions::FrameNames world_frames = prefixed();
  world_frames.odom = world_frames.world;
  world_frames.base_link = world_frames.ground_truth;
  EXPECT_EQ(messages.ground_truth.child_frame_id, std::string(kPrefix) + "base_link_ground_truth");
  const ros_conversions::OdometryCovariance exact{{0, 0, 0, 0, 0, 0}, {0, 0, 0, 0, 0, 0}};
  EXPECT_EQ(messages.ground_truth, ros_conversions::to_odometry(state, simulation.model(), world_frames, exact));
  const sensor_msgs::JointState joints = ros_conversions::to_joint_state(
      state, simulation.model(), ros_conversions::actuator_efforts(simulation), kPrefix);
  EXPECT_EQ(messages.joints, joints);
  ASSERT_EQ(messages.transforms.transforms.size(), 1u);
  EXPECT_EQ(messages.transforms.transforms[0], ros_conversions::to_transform(state, simulation.model(), prefixed()));
  IntegrationError error = ros_conversions::to_integration_error(state, simulation.diagnostics(), simulation.statistics(),
                                                                 simulation.integrator_name(), simulation.step_size(), 3e-6);
  error.accuracy_level = static_cast<std::uint8_t>(guard.level());
  error.accuracy_current_level = static_cast<std::uint8_t>(guard.current_level());
  error.accuracy_status = guard.summary();
  // Bytes, not ==: the local error estimate is NaN for birkhoff2 (no estimate), and NaN != NaN.
  EXPECT_EQ(serialized(messages.integration_error), serialized(error));
}

}  // namespace
}  // namespace birkhoff_cart
