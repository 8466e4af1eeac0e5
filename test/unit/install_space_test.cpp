// The install space works: checks/test_install.sh installs this built workspace into a
// temporary DESTDIR and runs cart_simulate, cart_sim --version, rospack, rosmsg and a 2 s
// `roslaunch birkhoff_cart sim.launch` from there, in an environment without the devel space or
// the source tree (about 15 s). Before the libraries had install rules, the installed
// cart_simulate could not load libbirkhoff_cart_core.so.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cstdlib>
#include <string>

#include "test_scenes.h"

namespace {

TEST(InstallSpace, RunsFromATemporaryPrefix) {
  // This binary is <workspace>/devel/lib/birkhoff_cart/install_space_test.
  const std::string binary_directory = birkhoff_cart_test::directory_of_this_binary();
  const std::string workspace = binary_directory + "/../../..";
  const std::string log = ::testing::TempDir() + "install_space_test.log";
  const std::string command = "BIRKHOFF_CART_WORKSPACE='" + workspace + "' bash '" BIRKHOFF_CART_SOURCE_DIR
                              "/checks/test_install.sh' --no-build > '" + log + "' 2>&1";
  const int status = std::system(command.c_str());
  const std::string output = birkhoff_cart_test::read_file(log);
  std::printf("%s", output.c_str());
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << output;
  EXPECT_NE(output.find(" passed, 0 failed"), std::string::npos) << output;
  std::remove(log.c_str());
}

}  // namespace
