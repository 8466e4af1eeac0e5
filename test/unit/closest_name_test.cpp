// closest_name: the edit distance, and a typo mapped to the name it misspells but an unrelated word
// to none (the "did you mean" of the nodes' parameter reports).
#include <gtest/gtest.h>

#include "birkhoff_cart/core/support/closest_name.h"

namespace birkhoff_cart {
namespace {

TEST(ClosestName, EditDistanceCountsInsertionsDeletionsAndSubstitutions) {
  EXPECT_EQ(edit_distance("", ""), 0u);
  EXPECT_EQ(edit_distance("publish_rate", "publish_rate"), 0u);
  EXPECT_EQ(edit_distance("publsh_rate", "publish_rate"), 1u);   // a letter dropped
  EXPECT_EQ(edit_distance("publish_rate", "publsh_rate"), 1u);   // symmetric
  EXPECT_EQ(edit_distance("kitten", "sitting"), 3u);
  EXPECT_EQ(edit_distance("abc", ""), 3u);
}

TEST(ClosestName, FindsTheNameATypoMisspellsAndNoneForAnotherWord) {
  const std::vector<std::string> known = {"publish_rate", "publish_tf", "cmd_vel_timeout", "steering_joint"};
  EXPECT_EQ(closest_name("publsh_rate", known), "publish_rate");
  EXPECT_EQ(closest_name("cmd_vel_timout", known), "cmd_vel_timeout");
  EXPECT_EQ(closest_name("stering_joint", known), "steering_joint");
  EXPECT_EQ(closest_name("publish_tff", known), "publish_tf");
  EXPECT_EQ(closest_name("frobnicate", known), "");
  EXPECT_EQ(closest_name("x", known), "");
  EXPECT_EQ(closest_name("anything", {}), "");
}

}  // namespace
}  // namespace birkhoff_cart
