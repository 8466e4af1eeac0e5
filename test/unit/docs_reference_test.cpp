// The user documentation against the code it describes: the CLI page shows exactly what
// `cart_simulate --help` prints, every registered integrator is documented, every relative link
// of README.md and docs/*.md reaches a file, no page or source tells the development history, and
// the README stays a short front door.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <regex>
#include <string>
#include <vector>

#include "birkhoff_cart/core/integrators/cart_stepper.h"
#include "test_scenes.h"

namespace {

using birkhoff_cart_test::cart_simulate_path;
using birkhoff_cart_test::read_file;

const std::string kSourceDirectory = BIRKHOFF_CART_SOURCE_DIR;

/// Everything a command writes to stdout.
std::string standard_output_of(const std::string& command) {
  std::string output;
  FILE* pipe = ::popen(command.c_str(), "r");
  if (pipe == nullptr) return output;
  char buffer[4096];
  std::size_t count = 0;
  while ((count = std::fread(buffer, 1, sizeof buffer, pipe)) > 0) output.append(buffer, count);
  ::pclose(pipe);
  return output;
}

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

TEST(DocsReference, TheReadmeIsAFrontDoorOfAtMost25KB) {
  const auto size = std::filesystem::file_size(kSourceDirectory + "/README.md");
  EXPECT_LE(size, 25u * 1024u) << "README.md is " << size
                               << " bytes: move reference material into docs/";
}

}  // namespace
