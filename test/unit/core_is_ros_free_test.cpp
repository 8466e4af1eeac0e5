// The core library is ROS-free: no core source includes a ROS header, and a program linked against
// the core (this test) loads no ROS shared library.
#include <gtest/gtest.h>
#include <link.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <vector>

#include "birkhoff_cart/core/physics/cart_model.h"

namespace {

int collect_loaded_object(struct dl_phdr_info* info, size_t /*size*/, void* data) {
  static_cast<std::vector<std::string>*>(data)->emplace_back(info->dlpi_name ? info->dlpi_name : "");
  return 0;
}

TEST(CoreIsRosFree, NoRosSharedLibraryIsLoaded) {
  // Use the core so that it is really linked in.
  const birkhoff_cart::CartModel model{birkhoff_cart::CartParameters{}};
  EXPECT_GT(model.inertia().mu, 0.0);
  std::vector<std::string> loaded;
  dl_iterate_phdr(collect_loaded_object, &loaded);
  ASSERT_FALSE(loaded.empty());
  for (const std::string& object : loaded) {
    for (const char* ros_library : {"libroscpp", "librosbag", "librostime", "libtf2_ros", "libcpp_common"}) {
      EXPECT_EQ(object.find(ros_library), std::string::npos) << object;
    }
  }
}

TEST(CoreIsRosFree, NoCoreSourceIncludesRosHeaders) {
  const std::filesystem::path root(BIRKHOFF_CART_SOURCE_DIR);
  const std::regex ros_include(
      R"(#\s*include\s*[<"](ros/|rosbag/|tf2_ros/|tf2/|std_msgs/|nav_msgs/|sensor_msgs/|geometry_msgs/|diagnostic_updater/|birkhoff_cart/IntegrationError))");
  int files_checked = 0;
  for (const char* directory : {"include/birkhoff_cart/core", "src/core", "src/apps"}) {
    for (const auto& entry : std::filesystem::recursive_directory_iterator(root / directory)) {
      if (!entry.is_regular_file()) continue;
      std::ifstream file(entry.path());
      std::string line;
      int line_number = 0;
      while (std::getline(file, line)) {
        ++line_number;
        EXPECT_FALSE(std::regex_search(line, ros_include)) << entry.path() << ":" << line_number << ": " << line;
      }
      ++files_checked;
    }
  }
  EXPECT_GT(files_checked, 5);
}

}  // namespace
