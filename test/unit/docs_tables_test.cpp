// The tables of the docs that list what the code defines, against the code: the registry's members
// (docs/integrators.md's member table and docs/scenes.md's list of `integrator.name` values are
// generated from integrator_registry(): generated_docs.h, BIRKHOFF_CART_WRITE_DOCS=1 rewrites
// them), the keys of every section of a scene (docs/scenes.md's key tables hold exactly the keys
// the scene reader allows, as its own "unknown key (allowed here: …)" refusal lists them), the
// effect table (docs/scenes.md: every row of effect_table() with its coefficient keys), the torque
// profiles (their table: every profile the reader knows, each row with the keys it allows), the shipped
// scenes (docs/scenes.md's table and the tolerance_sweep study cover every file of config/scenes/)
// and the counts of effects the pages state. A member, key, effect or scene added to the code
// without its row fails here, and so does a row the code no longer has.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "birkhoff_cart/core/physics/effect_library.h"
#include "birkhoff_cart/core/cart_binding/integrator_registry.h"
#include "birkhoff_cart/core/integrators/adaptive_refusal.h"
#include "birkhoff_cart/core/scene/scene.h"
#include "generated_docs.h"
#include "test_scenes.h"

namespace birkhoff_cart {
namespace {

using birkhoff_cart_test::minimal_scene;
using birkhoff_cart_test::read_file;

const std::string kSourceDirectory = BIRKHOFF_CART_SOURCE_DIR;

std::string page(const std::string& relative) { return read_file(kSourceDirectory + "/" + relative); }

std::string step_controls(const IntegratorEntry& entry) {
  std::string controls = entry.takes_tolerance() ? "fixed (its own steps inside h, for `tolerance`)" : "fixed";
  if (entry.reversible()) controls += ", reversible";
  if (entry.adaptive()) controls += ", adaptive";
  if (adaptive_refusal(entry.name) != nullptr) controls += " (adaptive refused: [accuracy.md](accuracy.md) §4.4)";
  return controls;
}

/// docs/integrators.md's member table: one row per registry member, in the registry's order.
std::string member_table() {
  std::string table =
      "| member | scheme | family | order | symmetric | step controls | stages evaluated together |\n"
      "|---|---|---|---|---|---|---|\n";
  for (const IntegratorEntry& entry : integrator_registry()) {
    table += std::string("| `") + entry.name + "` | " + entry.description + " | " + to_string(entry.kind) + " | " +
             std::to_string(entry.order) + " | " + (entry.symmetric ? "yes" : "no") + " | " + step_controls(entry) +
             " | " + (entry.vector_stages ? "yes" : "–") + " |\n";
  }
  return table;
}

/// docs/scenes.md's list of the values of `integrator.name`.
std::string member_names_line() {
  std::string line = "`integrator.name`, `--integrator` and `~integrator` take one of the " +
                     std::to_string(integrator_registry().size()) + " registry members: ";
  const auto names = integrator_names();
  for (std::size_t i = 0; i < names.size(); ++i) line += (i == 0 ? "`" : ", `") + names[i] + "`";
  return line + ".\n";
}

TEST(DocsTables, TheMemberTableOfIntegratorsMdIsTheRegistry) {
  EXPECT_TRUE(birkhoff_cart_test::docs_part_is_current("docs/integrators.md", "docs_tables_test", member_table()));
}

TEST(DocsTables, TheIntegratorNamesOfScenesMdAreTheRegistrys) {
  EXPECT_TRUE(birkhoff_cart_test::docs_part_is_current("docs/scenes.md", "docs_tables_test", member_names_line()));
}

/// The keys in backticks in the first column of the first table after `heading` ("`x`, `y`" → x, y).
std::set<std::string> first_column_after(const std::string& markdown, const std::string& heading) {
  std::set<std::string> keys;
  const auto at = markdown.find("\n" + heading + "\n");
  if (at == std::string::npos) return {"<no heading '" + heading + "'>"};
  auto line_start = markdown.find("\n|", at);
  // Header and separator rows first.
  line_start = markdown.find('\n', markdown.find('\n', line_start + 1) + 1);
  const std::regex quoted("`([^`]+)`");
  while (line_start != std::string::npos && markdown.compare(line_start, 2, "\n|") == 0) {
    const auto line_end = markdown.find('\n', line_start + 1);
    const std::string row = markdown.substr(line_start + 2, line_end - line_start - 2);
    const std::string first = row.substr(0, row.find(" |"));
    for (auto it = std::sregex_iterator(first.begin(), first.end(), quoted); it != std::sregex_iterator(); ++it) {
      keys.insert((*it)[1]);
    }
    line_start = line_end;
  }
  return keys;
}

/// The names the scene reader lists when it refuses the scene `text`: after `marker` ("allowed
/// here: " for an unknown key, "is not one of: " for an unknown choice), to the end of the list.
std::set<std::string> names_the_reader_lists(const std::string& text, const std::string& marker) {
  try {
    load_scene_text(text, "probe.yaml");
  } catch (const SceneError& error) {
    const std::string message = error.what();
    const auto from = message.find(marker);
    if (from == std::string::npos) return {"<no list in: " + message + ">"};
    const auto to = message.find_first_of(")\n", from);
    std::set<std::string> names;
    std::string list = message.substr(from + marker.size(), to == std::string::npos ? std::string::npos
                                                                                      : to - from - marker.size()) + ", ";
    for (std::size_t at = 0, comma; (comma = list.find(", ", at)) != std::string::npos; at = comma + 2) {
      names.insert(list.substr(at, comma - at));
    }
    return names;
  }
  return {"<the probe was accepted>"};
}

/// The keys the scene reader allows in `section` (after its line `anchor` in a valid scene, or
/// appended as a new section when `anchor` is empty), read from its refusal of an unknown key.
std::set<std::string> keys_the_reader_allows(const std::string& anchor, const std::string& section) {
  std::string text = minimal_scene("probe", "5.0");
  if (section.empty()) {
    text += "zz_probe_key: 1\n";
  } else if (!anchor.empty()) {
    text = birkhoff_cart_test::replaced_once(text, anchor, anchor + "  zz_probe_key: 1\n");
  } else {
    text += section + ":\n  zz_probe_key: 1\n";
  }
  return names_the_reader_lists(text, "allowed here: ");
}

TEST(DocsTables, EveryKeyTableOfScenesMdHoldsExactlyTheKeysTheReaderAllows) {
  const std::string scenes = page("docs/scenes.md");
  struct Section {
    const char* heading;
    const char* anchor;   // the section's line in minimal_scene(), "" to append the section
    const char* section;  // "" for the top level
  };
  const Section sections[] = {
      {"## Top-level keys", "", ""},
      {"## `cart` (all required, each finite and > 0)", "cart:\n", "cart"},
      {"## `initial_state`", "initial_state:\n", "initial_state"},
      {"## `integrator` (also `reference.integrator`)", "integrator:\n", "integrator"},
      {"## `reference`", "", "reference"},
      {"## `accuracy`", "", "accuracy"},
      {"## `odometry_sensor`", "", "odometry_sensor"},
      {"## `steering_actuator`, `drive_actuator`", "", "steering_actuator"},
      {"## `steering_actuator`, `drive_actuator`", "", "drive_actuator"},
      {"## `steering_end_stops`", "", "steering_end_stops"},
  };
  for (const Section& s : sections) {
    const auto allowed = keys_the_reader_allows(s.anchor, s.section);
    EXPECT_GE(allowed.size(), 2u) << s.section << ": " << *allowed.begin();
    EXPECT_EQ(first_column_after(scenes, s.heading), allowed)
        << "docs/scenes.md, " << s.heading << ": the table's keys differ from those the scene reader allows in '"
        << s.section << "'";
  }
}

TEST(DocsTables, TheEffectTableOfScenesMdIsTheEffectLibrarys) {
  const std::string scenes = page("docs/scenes.md");
  const auto names = effect_names();
  EXPECT_EQ(first_column_after(scenes, "## `effects`"), std::set<std::string>(names.begin(), names.end()));
  EXPECT_EQ(keys_the_reader_allows("", "effects"), std::set<std::string>(names.begin(), names.end()));
  for (const EffectEntry& entry : effect_table()) {
    const auto row_at = scenes.find("| `" + std::string(entry.name) + "` |");
    ASSERT_NE(row_at, std::string::npos) << entry.name;
    const std::string row = scenes.substr(row_at, scenes.find('\n', row_at) - row_at);
    EXPECT_NE(row.find(entry.equation), std::string::npos) << entry.name << "'s row does not cite " << entry.equation;
    for (const std::string& key : coefficient_keys(entry)) {
      EXPECT_NE(row.find("`" + key + "`"), std::string::npos) << entry.name << "'s row lacks its key " << key;
    }
    if (entry.takes_profile()) {
      EXPECT_NE(row.find("profile"), std::string::npos) << entry.name;
    }
  }
}

TEST(DocsTables, TheTorqueProfileTableOfScenesMdIsTheReaders) {
  const std::string scenes = page("docs/scenes.md");
  const std::string effect = minimal_scene("probe", "5.0") + "effects:\n  steering_torque:\n    profile: ";
  const auto profiles = names_the_reader_lists(effect + "zz_probe\n", "is not one of: ");
  EXPECT_GE(profiles.size(), 5u) << *profiles.begin();
  EXPECT_EQ(first_column_after(scenes, "### Torque profiles (`steering_torque`, `drive_torque`)"), profiles);
  for (const std::string& profile : profiles) {
    const auto row_at = scenes.find("| `" + profile + "` |");
    ASSERT_NE(row_at, std::string::npos) << profile;
    const std::string row = scenes.substr(row_at, scenes.find('\n', row_at) - row_at);
    for (const std::string& key : names_the_reader_lists(effect + profile + "\n    zz_probe_key: 1\n", "allowed here: ")) {
      if (key == "profile" || key == "enabled") continue;  // every profile's, stated above the table
      EXPECT_NE(row.find("`" + key + "`"), std::string::npos) << "the row of profile " << profile << " lacks its key " << key;
    }
  }
}

/// number_word(6) = "six": how the pages spell small counts.
std::string number_word(std::size_t n) {
  static const char* const kWords[] = {"zero", "one", "two", "three", "four", "five", "six", "seven", "eight",
                                       "nine", "ten", "eleven", "twelve", "thirteen", "fourteen", "fifteen"};
  return n < sizeof kWords / sizeof kWords[0] ? kWords[n] : std::to_string(n);
}

TEST(DocsTables, TheCountsOfEffectsThePagesStateAreTheTables) {
  const std::string effects = number_word(effect_table().size());
  EXPECT_NE(page("docs/birkhoffian.md").find("all " + effects + " effects on"), std::string::npos)
      << "docs/birkhoffian.md: the effect table has " << effect_table().size() << " effects";
  // README.md's "Scenes and effects" names every effect.
  const std::string readme = page("README.md");
  const std::string scenes_and_effects = readme.substr(readme.find("## Scenes and effects"));
  for (const std::string& name : effect_names()) {
    EXPECT_NE(scenes_and_effects.find("`" + name + "`"), std::string::npos) << "README.md does not name the effect " << name;
  }
}

std::set<std::string> shipped_scenes() {
  std::set<std::string> scenes;
  for (const auto& entry : std::filesystem::directory_iterator(kSourceDirectory + "/config/scenes")) {
    if (entry.path().extension() == ".yaml") scenes.insert(entry.path().stem().string());
  }
  return scenes;
}

TEST(DocsTables, TheShippedScenesTableAndTheToleranceSweepCoverEveryShippedScene) {
  const auto shipped = shipped_scenes();
  ASSERT_GE(shipped.size(), 10u);
  EXPECT_EQ(first_column_after(page("docs/scenes.md"), "## Shipped scenes"), shipped)
      << "docs/scenes.md's table of shipped scenes differs from config/scenes/";
  // docs/accuracy.md §4.1, docs/integrators.md and docs/studies.md say the sweep covers every one.
  std::set<std::string> swept;
  for (const auto& experiment : YAML::LoadFile(kSourceDirectory + "/bench/studies/tolerance_sweep.yaml")["experiments"]) {
    for (const auto& scene : experiment["scenes"]) swept.insert(scene.as<std::string>());
  }
  EXPECT_EQ(swept, shipped) << "bench/studies/tolerance_sweep.yaml no longer covers every shipped scene";
}

}  // namespace
}  // namespace birkhoff_cart
