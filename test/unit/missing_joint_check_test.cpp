// MissingJointCheck (missing_joint_check.h): a joint name refused only after its grace, by name.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "birkhoff_cart/core/node_logic/missing_joint_check.h"

namespace birkhoff_cart {
namespace {

TEST(MissingJointCheck, RefusesAfterTheGraceNamingTheJointsAndTheClosest) {
  MissingJointCheck check("stering_joint", 1.0);
  const std::vector<std::string> names = {"steering_joint", "rear_left_wheel_joint"};
  EXPECT_FALSE(check.find(names));
  check.note_missing(names, 10.0);
  check.note_missing({"other_joint"}, 10.2);  // only the first message counts
  EXPECT_FALSE(check.refusal(10.5, "~steering_joint", "/joint_states"));  // within the grace
  const std::optional<std::string> refusal = check.refusal(11.0, "~steering_joint", "/joint_states");
  ASSERT_TRUE(refusal);
  EXPECT_EQ(*refusal,
            "joint 'stering_joint' (~steering_joint) is not in /joint_states, which names steering_joint, "
            "rear_left_wheel_joint (did you mean 'steering_joint'?): without the steering angle the controller "
            "cannot steer, so it does not run");
}

TEST(MissingJointCheck, AMessageWithTheJointEndsTheCheck) {
  MissingJointCheck check("steering_joint", 1.0);
  EXPECT_FALSE(check.find({"gripper_joint"}));  // another publisher's partial joint_states
  check.note_missing({"gripper_joint"}, 0.0);
  const std::optional<std::size_t> index = check.find({"front_left_wheel_joint", "steering_joint"});
  ASSERT_TRUE(index);
  EXPECT_EQ(*index, 1u);
  EXPECT_TRUE(check.seen());
  EXPECT_FALSE(check.refusal(5.0, "~steering_joint", "/joint_states"));
  MissingJointCheck silent("steering_joint", 1.0);
  EXPECT_FALSE(silent.refusal(100.0, "~steering_joint", "/joint_states"));  // no message yet: nothing to refuse
}

}  // namespace
}  // namespace birkhoff_cart
