// The list of parameters cart_sim reads (cart_sim_parameter_names(), behind its "did you mean"
// report of a misspelled parameter) is the list load_parameters() reads: every name it passes to a
// reader appears in the list and every listed name is read, so a parameter added later is not
// reported as a typo and a parameter removed is no longer accepted in silence.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <regex>
#include <set>
#include <string>

#include "birkhoff_cart/ros/cart_sim_parameters.h"

namespace birkhoff_cart {
namespace {

TEST(CartSimParameterNames, AreExactlyTheNamesLoadParametersReads) {
  std::ifstream file(std::string(BIRKHOFF_CART_SOURCE_DIR) + "/src/ros/cart_sim_parameters.cpp");
  ASSERT_TRUE(file.good());
  const std::string source((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  const auto body_start = source.find("CartSimParameters load_parameters(");
  ASSERT_NE(body_start, std::string::npos);
  const std::string body = source.substr(body_start);
  // read_parameter<T>(p, "name", ...), read_double_parameter(p, "name", ...), read_variances(p, "name", ...)
  const std::regex read(R"(read_[a-z_]+(<[^(]*>)?\(\s*p,\s*\"([a-z_0-9]+)\")");
  std::set<std::string> read_names;
  for (auto it = std::sregex_iterator(body.begin(), body.end(), read); it != std::sregex_iterator(); ++it) {
    read_names.insert((*it)[2]);
  }
  ASSERT_GT(read_names.size(), 30u) << "the pattern no longer matches the readers";
  std::set<std::string> listed(cart_sim_parameter_names().begin(), cart_sim_parameter_names().end());
  // Read elsewhere: ~end_launch (nodes/cart_sim.cpp) and ~accuracy/... (accuracy_reporting.cpp).
  for (const char* elsewhere : {"end_launch", "accuracy/"}) {
    EXPECT_EQ(listed.erase(elsewhere), 1u) << elsewhere;
  }
  for (const std::string& name : read_names) EXPECT_EQ(listed.count(name), 1u) << "~" << name << " is read but not listed";
  for (const std::string& name : listed) EXPECT_EQ(read_names.count(name), 1u) << "~" << name << " is listed but not read";
}

}  // namespace
}  // namespace birkhoff_cart
