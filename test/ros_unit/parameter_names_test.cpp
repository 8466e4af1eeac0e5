// The list of parameters cart_sim reads (cart_sim_parameter_names(), behind its "did you mean"
// report of a misspelled parameter) is the list load_parameters() reads: every row of the parameter
// table (parameter_rows() in cart_sim_parameters.cpp) reads the name it is listed under and no other,
// and every listed name is read, so a parameter added later is not reported as a typo and a
// parameter removed is no longer accepted in silence. And the parameter
// table of docs/ros_interface.md ("### Parameters (all private)" of cart_sim) holds exactly that list:
// every `~name` of its first column is a name cart_sim reads, and every name it reads has its row
// (dynamic_reconfigure's copies of the guard limits as the `<quantity>_warn` / `<quantity>_error`
// of a quantity the `~accuracy/<quantity>` row names). The same for cmd_vel_controller's table and
// cmd_vel_controller_parameter_names().
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "birkhoff_cart/ros/cart_sim_parameters.h"
#include "birkhoff_cart/ros/cmd_vel_controller_node.h"

namespace birkhoff_cart {
namespace {

TEST(CartSimParameterNames, AreExactlyTheNamesLoadParametersReads) {
  std::ifstream file(std::string(BIRKHOFF_CART_SOURCE_DIR) + "/src/ros/cart_sim_parameters.cpp");
  ASSERT_TRUE(file.good());
  const std::string source((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  const auto body_start = source.find("const std::vector<ParameterRow>& parameter_rows()");
  ASSERT_NE(body_start, std::string::npos);
  const std::string body = source.substr(body_start);
  // read_parameter<T>(p, "name", ...), read_double_parameter(p, "name", ...), read_variances(p, "name", ...)
  const std::regex read(R"(read_[a-z_]+(<[^(]*>)?\(\s*p,\s*\"([a-z_0-9]+)\")");
  // A row of the table: {"name", [](Node p, Parameters parameters) {...}}; what it reads runs to the next row.
  const std::regex row_start(R"(\{\"([a-z_0-9]+)\",\s*\[\]\(Node p, Parameters parameters\))");
  std::vector<std::pair<std::string, std::size_t>> rows;
  for (auto it = std::sregex_iterator(body.begin(), body.end(), row_start); it != std::sregex_iterator(); ++it) {
    rows.emplace_back((*it)[1], static_cast<std::size_t>(it->position()));
  }
  ASSERT_GE(rows.size(), 30u) << "the pattern no longer matches the table's rows";
  std::set<std::string> read_names;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const std::size_t end = i + 1 < rows.size() ? rows[i + 1].second : body.find("check_together", rows[i].second);
    const std::string text = body.substr(rows[i].second, end - rows[i].second);
    std::set<std::string> in_row;
    for (auto it = std::sregex_iterator(text.begin(), text.end(), read); it != std::sregex_iterator(); ++it) {
      in_row.insert((*it)[2]);
    }
    EXPECT_EQ(in_row, std::set<std::string>{rows[i].first}) << "the row of ~" << rows[i].first << " reads other names";
    read_names.insert(in_row.begin(), in_row.end());
  }
  std::set<std::string> listed(cart_sim_parameter_names().begin(), cart_sim_parameter_names().end());
  // Read elsewhere: ~end_launch (nodes/cart_sim.cpp); ~accuracy/... and the residual thresholds
  // (accuracy_reporting.cpp); dynamic_reconfigure's own copies (cfg/CartSim.cfg). Each must occur,
  // quoted, in its file.
  const auto text_of = [](const std::string& relative) {
    std::ifstream in(std::string(BIRKHOFF_CART_SOURCE_DIR) + "/" + relative);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  };
  const std::string main_source = text_of("src/ros/nodes/cart_sim.cpp");
  const std::string accuracy_source = text_of("src/ros/accuracy_reporting.cpp");
  const std::string reconfigure_cfg = text_of("cfg/CartSim.cfg");
  ASSERT_FALSE(main_source.empty() || accuracy_source.empty() || reconfigure_cfg.empty());
  const std::pair<const char*, const std::string*> elsewhere[] = {
      {"end_launch", &main_source},
      {"accuracy/", &accuracy_source},
      {"energy_residual_warn", &accuracy_source},
      {"energy_residual_error", &accuracy_source},
      {"p2_residual_warn", &accuracy_source},
      {"p2_residual_error", &accuracy_source},
      {"constraint_residual_warn", &accuracy_source},
      {"constraint_residual_error", &accuracy_source},
      {"energy_balance_relative_warn", &reconfigure_cfg},
      {"energy_balance_relative_error", &reconfigure_cfg},
      {"p2_balance_warn", &reconfigure_cfg},
      {"p2_balance_error", &reconfigure_cfg},
      {"constraint_warn", &reconfigure_cfg},
      {"constraint_error", &reconfigure_cfg},
      {"estimated_error_warn", &reconfigure_cfg},
      {"estimated_error_error", &reconfigure_cfg},
      {"energy_balance_warn", &reconfigure_cfg},
      {"energy_balance_error", &reconfigure_cfg},
  };
  for (const auto& [name, source_text] : elsewhere) {
    EXPECT_EQ(listed.erase(name), 1u) << name << " is not listed";
    EXPECT_NE(source_text->find(std::string(name) + "\""), std::string::npos) << name << " is not read where it should be";
  }
  for (const std::string& name : read_names) EXPECT_EQ(listed.count(name), 1u) << "~" << name << " is read but not listed";
  for (const std::string& name : listed) EXPECT_EQ(read_names.count(name), 1u) << "~" << name << " is listed but not read";
}

/// The `~name`s in the first column of the first table after `heading` (searched from `section`) of
/// docs/ros_interface.md (`~accuracy/<quantity>` gives "accuracy/"), each with its row.
std::map<std::string, std::string> documented_parameters(const std::string& section, const std::string& heading) {
  std::ifstream file(std::string(BIRKHOFF_CART_SOURCE_DIR) + "/docs/ros_interface.md");
  const std::string page((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  const auto at = page.find(heading, page.find(section));
  if (page.find(section) == std::string::npos || at == std::string::npos) return {};
  const auto table = page.find("\n|", at);
  const auto table_end = page.find("\n\n", table);
  std::istringstream rows(page.substr(table + 1, table_end - table - 1));
  std::map<std::string, std::string> documented;
  const std::regex parameter(R"(`~([a-z_0-9/]+)(<quantity>)?`)");
  for (std::string row; std::getline(rows, row);) {
    const std::string first = row.substr(0, row.find(" |", 2));
    for (auto it = std::sregex_iterator(first.begin(), first.end(), parameter); it != std::sregex_iterator(); ++it) {
      documented[(*it)[1]] = row;
    }
  }
  return documented;
}

TEST(CartSimParameterNames, AreTheRowsOfTheParameterTableOfRosInterfaceMd) {
  const auto documented = documented_parameters("## Node `cart_sim`", "### Parameters (all private)");
  ASSERT_GE(documented.size(), 30u) << "the pattern no longer finds the table's rows";
  const std::set<std::string> listed(cart_sim_parameter_names().begin(), cart_sim_parameter_names().end());
  for (const auto& [name, row] : documented) EXPECT_EQ(listed.count(name), 1u) << "~" << name << " is documented but not read";
  ASSERT_EQ(documented.count("accuracy/"), 1u) << "no row of ~accuracy/<quantity>";
  const std::string& accuracy_row = documented.at("accuracy/");
  for (const std::string& name : listed) {
    if (documented.count(name) != 0) continue;
    // dynamic_reconfigure's copies: <quantity>_warn, <quantity>_error of a quantity the row names.
    std::smatch copy;
    const bool is_copy = std::regex_match(name, copy, std::regex("(.+)_(warn|error)")) &&
                         accuracy_row.find("`" + copy[1].str() + "`") != std::string::npos;
    EXPECT_TRUE(is_copy) << "~" << name << " is read by cart_sim but has no row in docs/ros_interface.md";
  }
}

TEST(CmdVelControllerParameterNames, AreTheRowsOfItsParameterTableOfRosInterfaceMd) {
  const auto documented = documented_parameters("## Node `cmd_vel_controller`", "| parameter | unit | default | meaning |");
  ASSERT_GE(documented.size(), 20u) << "the pattern no longer finds the table's rows";
  const auto& names = cmd_vel_controller_parameter_names();
  const std::set<std::string> listed(names.begin(), names.end());
  for (const auto& [name, row] : documented) EXPECT_EQ(listed.count(name), 1u) << "~" << name << " is documented but not read";
  for (const std::string& name : listed) {
    // dynamic_reconfigure's copies spell a documented name with '_' for '/' (linear_x_max_velocity).
    bool documented_as = documented.count(name) != 0;
    for (const auto& [documented_name, row] : documented) {
      documented_as = documented_as || std::regex_replace(documented_name, std::regex("/"), "_") == name;
    }
    EXPECT_TRUE(documented_as) << "~" << name << " is read by cmd_vel_controller but has no row in docs/ros_interface.md";
  }
}

}  // namespace
}  // namespace birkhoff_cart
