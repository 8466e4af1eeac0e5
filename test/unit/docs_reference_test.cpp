// The user documentation against the code it describes: the CLI page shows exactly what
// `cart_simulate --help` prints, every registered integrator is documented, every relative link
// of README.md and docs/*.md reaches a file, no page or source tells the development history, the
// README stays a short front door, and the counts the pages state are the counts of the files and
// tests they describe.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <regex>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "birkhoff_cart/core/cart_binding/cart_stepper.h"
#include "test_scenes.h"

namespace {

using birkhoff_cart_test::cart_simulate_path;
using birkhoff_cart_test::read_file;
using birkhoff_cart_test::standard_output_of;

const std::string kSourceDirectory = BIRKHOFF_CART_SOURCE_DIR;

/// The first fenced block (```) after `heading` in `markdown`, without its fences.
std::string fenced_block_after(const std::string& markdown, const std::string& heading) {
  const auto at_heading = markdown.find(heading);
  if (at_heading == std::string::npos) return "<no heading '" + heading + "'>";
  const auto open = markdown.find("```", at_heading);
  if (open == std::string::npos) return "<no fenced block>";
  const auto body = markdown.find('\n', open) + 1;
  const auto close = markdown.find("\n```", body);
  if (close == std::string::npos) return "<unclosed fenced block>";
  return markdown.substr(body, close - body + 1);
}

/// The user-facing markdown pages: README.md, CHANGELOG.md and docs/*.md.
std::vector<std::filesystem::path> markdown_pages() {
  std::vector<std::filesystem::path> pages{kSourceDirectory + "/README.md",
                                           kSourceDirectory + "/CHANGELOG.md"};
  for (const auto& entry : std::filesystem::directory_iterator(kSourceDirectory + "/docs")) {
    if (entry.path().extension() == ".md") pages.push_back(entry.path());
  }
  return pages;
}

TEST(DocsReference, TheCliPageShowsExactlyWhatHelpPrints) {
  const std::string help = standard_output_of("'" + cart_simulate_path() + "' --help");
  ASSERT_NE(help.find("usage: cart_simulate"), std::string::npos) << help;
  const std::string page = read_file(kSourceDirectory + "/docs/cli.md");
  EXPECT_EQ(fenced_block_after(page, "## Usage"), help)
      << "docs/cli.md's usage block differs from `cart_simulate --help`: paste the new output";
}

TEST(DocsReference, EveryRegisteredIntegratorIsDocumentedAndListedByHelp) {
  const std::string page = read_file(kSourceDirectory + "/docs/integrators.md");
  const std::string help = standard_output_of("'" + cart_simulate_path() + "' --help");
  const auto names = birkhoff_cart::integrator_names();
  ASSERT_FALSE(names.empty());
  for (const auto& name : names) {
    EXPECT_NE(page.find("`" + name + "`"), std::string::npos) << name << " missing in docs/integrators.md";
    EXPECT_NE(help.find(name), std::string::npos) << name << " missing in cart_simulate --help";
  }
}

TEST(DocsReference, EveryRelativeLinkReachesAFile) {
  // [text](target) with a target that is not a URL or a bare anchor; the anchor part is dropped.
  const std::regex link(R"(\]\(([^)#\s]+)(#[^)\s]*)?\))");
  int links = 0;
  for (const auto& page : markdown_pages()) {
    const std::string text = read_file(page.string());
    for (auto match = std::sregex_iterator(text.begin(), text.end(), link);
         match != std::sregex_iterator(); ++match) {
      const std::string target = (*match)[1];
      if (target.rfind("http://", 0) == 0 || target.rfind("https://", 0) == 0 ||
          target.rfind("mailto:", 0) == 0) {
        continue;
      }
      ++links;
      EXPECT_TRUE(std::filesystem::exists(page.parent_path() / target))
          << page.filename().string() << " links to " << target << ", which does not exist";
    }
  }
  EXPECT_GT(links, 20) << "the link pattern found too few links to be checking anything";
}

TEST(DocsReference, NoSourceOrPageTellsTheDevelopmentHistory) {
  // History belongs in CHANGELOG.md and the commit messages; code, tests and docs state the
  // behaviour they implement or check.
  const std::regex history(R"((\b[Ii]ssues? [0-9]+|\buser trial\b|\b[Rr]ound [0-9]\b|\blate rerun\b))");
  int files = 0;
  for (const char* part : {"src", "include", "test", "scripts", "checks", "bench", "launch", "config", "docs"}) {
    for (const auto& entry : std::filesystem::recursive_directory_iterator(kSourceDirectory + "/" + part)) {
      if (!entry.is_regular_file() || entry.path().extension() == ".png" || entry.path().extension() == ".jsonl") continue;
      ++files;
      const std::string text = read_file(entry.path().string());
      std::smatch found;
      EXPECT_FALSE(std::regex_search(text, found, history))
          << entry.path().string() << " tells the development history: '" << found.str() << "'";
    }
  }
  const std::string readme = read_file(kSourceDirectory + "/README.md");
  EXPECT_FALSE(std::regex_search(readme, history)) << "README.md tells the development history";
  EXPECT_GT(files, 100);
}

/// "eleven" for 11 (the README spells small counts).
std::string number_word(std::size_t n) {
  static const char* const kWords[] = {"zero", "one",   "two",    "three",  "four",    "five",    "six",
                                       "seven", "eight", "nine",  "ten",    "eleven",  "twelve",  "thirteen",
                                       "fourteen", "fifteen", "sixteen", "seventeen", "eighteen", "nineteen", "twenty"};
  return n < sizeof kWords / sizeof kWords[0] ? kWords[n] : std::to_string(n);
}

/// Test cases of a gtest binary beside this one (--gtest_list_tests).
std::size_t gtest_cases(const std::string& binary) {
  const std::string listing =
      standard_output_of("'" + birkhoff_cart_test::directory_of_this_binary() + "/" + binary + "' --gtest_list_tests");
  std::size_t cases = 0;
  for (std::size_t at = 0; (at = listing.find("\n  ", at)) != std::string::npos; ++at) ++cases;
  return cases;
}

std::size_t study_runs(const std::string& study_file, const char* family_key) {
  const YAML::Node study = YAML::LoadFile(kSourceDirectory + "/" + study_file);
  const YAML::Node experiment = study["experiments"][0];
  const std::size_t count = experiment[family_key]["count"].as<std::size_t>();
  return experiment["integrators"] ? count * experiment["integrators"].size() : count;
}

TEST(DocsReference, TheCountsThePagesStateAreTheCountsOfTheFiles) {
  const std::string readme = read_file(kSourceDirectory + "/README.md");
  std::size_t scenes = 0;
  for (const auto& entry : std::filesystem::directory_iterator(kSourceDirectory + "/config/scenes")) {
    scenes += entry.path().extension() == ".yaml" ? 1 : 0;
  }
  EXPECT_NE(readme.find("ships " + number_word(scenes) + " scenes"), std::string::npos)
      << "config/scenes/ holds " << scenes << " scenes";
  const std::size_t cart_keys = YAML::LoadFile(kSourceDirectory + "/config/scenes/default.yaml")["cart"].size();
  EXPECT_NE(readme.find("the cart's " + std::to_string(cart_keys) + " physical parameters"), std::string::npos)
      << "a scene's cart map has " << cart_keys << " keys";
  EXPECT_NE(read_file(kSourceDirectory + "/docs/scenes.md").find("the " + std::to_string(cart_keys) + " physical parameters"),
            std::string::npos);
  EXPECT_NE(readme.find(std::to_string(study_runs("bench/studies/random_carts.yaml", "random_scenes")) +
                        " runs of random carts"),
            std::string::npos)
      << "bench/studies/random_carts.yaml changed its size";
  EXPECT_NE(readme.find(std::to_string(study_runs("checks/studies/cli_sweep.yaml", "random_runs")) +
                        " random CLI inputs"),
            std::string::npos)
      << "checks/studies/cli_sweep.yaml changed its size";
  const std::string hard_cases = read_file(kSourceDirectory + "/docs/hard_cases.md");
  EXPECT_NE(hard_cases.find("hard_cases_test.cpp` (§1–§6, " + std::to_string(gtest_cases("hard_cases_test")) + " cases"),
            std::string::npos)
      << "hard_cases_test has " << gtest_cases("hard_cases_test") << " cases";
}

TEST(DocsReference, TheReadmeIsAFrontDoorOfAtMost25KB) {
  const auto size = std::filesystem::file_size(kSourceDirectory + "/README.md");
  EXPECT_LE(size, 25u * 1024u) << "README.md is " << size
                               << " bytes: move reference material into docs/";
}

}  // namespace
