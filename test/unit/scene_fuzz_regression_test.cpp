// Every finding of the scene-reader fuzzer (checks/fuzz_scenes.sh) kept as a regression: each file
// in test/fuzz/regressions/ must meet the fuzz target's contract (test/fuzz/scene_reader_fuzz.cpp):
// load_scene() returns or throws a one-line SceneError; an accepted scene makes a Simulation or is
// refused with std::invalid_argument; its first steps succeed with a finite state or throw
// StepError. The file name says what the fuzzer found.
#include <gtest/gtest.h>

#include <dirent.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "birkhoff_cart/core/cart_binding/cart_stepper.h"
#include "birkhoff_cart/core/scene/scene.h"
#include "birkhoff_cart/core/run/simulation.h"

namespace birkhoff_cart {
namespace {

const std::string kDirectory = std::string(BIRKHOFF_CART_SOURCE_DIR) + "/test/fuzz/regressions/";

std::vector<std::string> regression_files() {
  std::vector<std::string> names;
  if (DIR* directory = opendir(kDirectory.c_str())) {
    while (const dirent* entry = readdir(directory)) {
      const std::string name = entry->d_name;
      if (name.size() > 5 && name.substr(name.size() - 5) == ".yaml") names.push_back(name);
    }
    closedir(directory);
  }
  std::sort(names.begin(), names.end());
  return names;
}

TEST(SceneFuzzRegressions, EveryFindingMeetsTheReaderContract) {
  const std::vector<std::string> names = regression_files();
  ASSERT_FALSE(names.empty()) << "no regression files in " << kDirectory;
  for (const std::string& name : names) {
    SCOPED_TRACE(name);
    Scene scene;
    try {
      scene = load_scene(kDirectory + name);
    } catch (const SceneError& error) {
      const std::string message = error.what();
      for (char character : message) {
        EXPECT_GE(static_cast<unsigned char>(character), 0x20) << "a control character in: " << message;
      }
      continue;
    }
    try {
      Simulation simulation(scene);
      for (int step = 0; step < 3 && simulation.state().time < simulation.end_time(); ++step) {
        simulation.step();
        EXPECT_TRUE(std::isfinite(simulation.state().x) && std::isfinite(simulation.state().forward_speed));
      }
    } catch (const std::invalid_argument&) {
    } catch (const StepError&) {
    }
  }
}

}  // namespace
}  // namespace birkhoff_cart
