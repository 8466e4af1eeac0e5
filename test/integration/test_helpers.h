// Small helpers shared by the rostest nodes: waiting on a condition while spinning (wall-clock
// timeouts only guard against hangs; the conditions are messages and sim time), and running a
// second cart_sim as a child process (start, wait for its exit) with the files it leaves behind
// (existence, size, text).
#pragma once

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include <ros/ros.h>
#include <std_srvs/SetBool.h>

namespace birkhoff_cart_test {

/// Spins until `condition` holds or `timeout` [s of wall time] passes. Returns the condition.
inline bool wait_for(const std::function<bool()>& condition, double timeout) {
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(timeout);
  while (ros::ok() && ros::WallTime::now() < deadline) {
    ros::spinOnce();
    if (condition()) return true;
    ros::WallDuration(0.002).sleep();
  }
  ros::spinOnce();
  return condition();
}

/// Calls cart_sim's ~pause service. Returns false when the service is missing or fails.
inline bool set_paused(const std::string& service, bool paused) {
  if (!ros::service::waitForService(service, ros::Duration(20.0))) return false;
  std_srvs::SetBool call;
  call.request.data = paused;
  return ros::service::call(service, call) && call.response.success;
}

/// An executable of this package, beside the test executable (devel/lib/birkhoff_cart/), found
/// through /proc/self/exe. Not through rosrun: it searches the whole package tree and may find
/// several workspaces' builds.
inline std::string package_executable(const std::string& name) {
  std::array<char, 4096> path{};
  const ssize_t length = ::readlink("/proc/self/exe", path.data(), path.size() - 1);
  std::string self(path.data(), length > 0 ? static_cast<std::size_t>(length) : 0);
  return self.substr(0, self.find_last_of('/') + 1) + name;
}

inline std::string cart_sim_executable() { return package_executable("cart_sim"); }

/// Starts the package's executable `name` (or the executable at `name` when it is an absolute path) as a child process (fork + execv) with `arguments` (ROS
/// remappings and _private:=value parameters). With a non-empty `log` its stdout and stderr go to
/// that file; otherwise they stay the test's. Returns the child's pid (≤ 0 when fork failed); a
/// child that cannot exec exits 127.
inline pid_t start_program(const std::string& name, const std::vector<std::string>& arguments,
                           const std::string& log = "") {
  const std::string executable = !name.empty() && name.front() == '/' ? name : package_executable(name);
  std::vector<std::string> storage = {executable};
  storage.insert(storage.end(), arguments.begin(), arguments.end());
  const pid_t pid = ::fork();
  if (pid == 0) {
    if (!log.empty()) {
      const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      if (fd >= 0) {
        ::dup2(fd, 1);
        ::dup2(fd, 2);
      }
    }
    std::vector<char*> argv;
    for (auto& argument : storage) argv.push_back(argument.data());
    argv.push_back(nullptr);
    ::execv(executable.c_str(), argv.data());
    ::_exit(127);
  }
  return pid;
}

/// start_program("cart_sim", ...).
inline pid_t start_cart_sim(const std::vector<std::string>& arguments, const std::string& log = "") {
  return start_program("cart_sim", arguments, log);
}

/// Waits up to `timeout` [s of wall time] for the child `pid` and returns its exit status; −1 when
/// it died of a signal or did not exit in time (then it is killed with SIGKILL and reaped).
inline int wait_exit(pid_t pid, double timeout) {
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(timeout);
  while (ros::WallTime::now() < deadline) {
    int status = 0;
    if (::waitpid(pid, &status, WNOHANG) == pid) return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    ros::WallDuration(0.02).sleep();
  }
  ::kill(pid, SIGKILL);
  ::waitpid(pid, nullptr, 0);
  return -1;
}

/// True when `path` exists (a bag under its final name, or its ".active" file while recording).
inline bool file_exists(const std::string& path) {
  struct stat info;
  return ::stat(path.c_str(), &info) == 0;
}

/// Size of the file at `path` [bytes]; −1 when it does not exist.
inline long file_size(const std::string& path) {
  struct stat info;
  return ::stat(path.c_str(), &info) == 0 ? static_cast<long>(info.st_size) : -1;
}

/// The whole text of the file at `path` ("" when it cannot be read).
inline std::string read_file(const std::string& path) {
  std::ifstream file(path);
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

/// Runs the shell `command` with stderr merged into stdout, appends what it printed to `output`,
/// and returns its exit status (−1 when it could not run or died of a signal).
inline int run_command(const std::string& command, std::string* output) {
  FILE* pipe = ::popen((command + " 2>&1").c_str(), "r");
  if (!pipe) return -1;
  std::array<char, 512> buffer;
  while (std::fgets(buffer.data(), buffer.size(), pipe)) *output += buffer.data();
  const int status = ::pclose(pipe);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace birkhoff_cart_test
