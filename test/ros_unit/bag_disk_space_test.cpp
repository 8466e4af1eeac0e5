// The bag recorder's free-space check (cart_sim's ~min_free_disk_space, docs/hard_cases.md §10):
// the pure decision, the bag's directory, statvfs, and a recorder that refuses to open (creating
// nothing) when the minimum is not met. No master needed.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <cstdint>
#include <limits>
#include <string>

#include "birkhoff_cart/ros/bag_recorder.h"

namespace birkhoff_cart {
namespace {

constexpr std::uint64_t kMebibyte = 1u << 20;  // [bytes]

bool exists(const std::string& path) {
  struct stat info;
  return ::stat(path.c_str(), &info) == 0;
}

TEST(DiskSpaceShortage, EnoughSpaceIsNoShortage) {
  EXPECT_EQ(disk_space_shortage("/data", 100 * kMebibyte, 16 * kMebibyte), "");
  EXPECT_EQ(disk_space_shortage("/data", 16 * kMebibyte, 16 * kMebibyte), "");  // the minimum itself is enough
}

TEST(DiskSpaceShortage, BelowTheMinimumNamesDirectoryFreeBytesAndMinimum) {
  const std::string message = disk_space_shortage("/mnt/small", 262144, 16777216);
  ASSERT_FALSE(message.empty());
  EXPECT_NE(message.find("/mnt/small"), std::string::npos) << message;
  EXPECT_NE(message.find("262144 bytes free"), std::string::npos) << message;
  EXPECT_NE(message.find("16777216 bytes"), std::string::npos) << message;
  EXPECT_NE(disk_space_shortage("/d", 16 * kMebibyte - 1, 16 * kMebibyte), "");  // one byte short
  EXPECT_NE(disk_space_shortage("/d", 0, 1), "");
}

TEST(DiskSpaceShortage, ZeroMinimumDisablesTheCheck) {
  EXPECT_EQ(disk_space_shortage("/full", 0, 0), "");
}

TEST(BagDirectory, IsTheDirectoryPartOfThePath) {
  EXPECT_EQ(bag_directory("/tmp/run/cart.bag"), "/tmp/run");
  EXPECT_EQ(bag_directory("output/main.bag"), "output");
  EXPECT_EQ(bag_directory("cart.bag"), ".");
  EXPECT_EQ(bag_directory("/cart.bag"), "/");
}

TEST(FreeDiskSpace, ReadsAnExistingDirectoryAndNamesAMissingOne) {
  EXPECT_NO_THROW(free_disk_space("/tmp"));
  try {
    free_disk_space("/nonexistent_directory_for_bag_disk_space_test");
    FAIL() << "statvfs of a missing directory should throw";
  } catch (const BagRecorderError& error) {
    EXPECT_NE(std::string(error.what()).find("/nonexistent_directory_for_bag_disk_space_test"), std::string::npos)
        << error.what();
  }
}

TEST(BagRecorderDiskSpace, RefusesToOpenBelowTheMinimumAndCreatesNothing) {
  const std::string path = "/tmp/bag_disk_space_test_" + std::to_string(::getpid()) + ".bag";
  try {
    BagRecorder recorder(path, BagRecorder::Compression::kLz4, std::numeric_limits<std::uint64_t>::max());
    FAIL() << "no file system has 2^64 - 1 bytes free";
  } catch (const BagRecorderError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find(path), std::string::npos) << message;
    EXPECT_NE(message.find("bytes free in /tmp"), std::string::npos) << message;
    EXPECT_NE(message.find(std::to_string(std::numeric_limits<std::uint64_t>::max())), std::string::npos) << message;
  }
  EXPECT_FALSE(exists(path + ".active"));
  EXPECT_FALSE(exists(path));
}

TEST(BagRecorderDiskSpace, OpensWhenTheCheckIsDisabledOrMet) {
  const std::string path = "/tmp/bag_disk_space_test_open_" + std::to_string(::getpid()) + ".bag";
  for (const std::uint64_t minimum : {std::uint64_t{0}, std::uint64_t{1}}) {
    {
      BagRecorder recorder(path, BagRecorder::Compression::kLz4, minimum);
      EXPECT_TRUE(recorder.is_open());
      EXPECT_TRUE(exists(path + ".active"));
    }
    EXPECT_TRUE(exists(path));  // closed and renamed by the destructor
    ::unlink(path.c_str());
  }
}

}  // namespace
}  // namespace birkhoff_cart
