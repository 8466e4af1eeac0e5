// SIGINT/SIGTERM as a shutdown request (see shutdown_signals.h).
#include "birkhoff_cart/ros/shutdown_signals.h"

#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <csignal>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>
#include <thread>

#include <ros/init.h>

namespace birkhoff_cart {
namespace {

std::atomic<int> g_shutdown_signals{0};
std::atomic<int> g_polling_loops{0};  ///< SignalsPolled alive
static_assert(std::atomic<int>::is_always_lock_free, "the signal handler reads atomics");

extern "C" void on_shutdown_signal(int /*signal*/) {
  if (g_shutdown_signals.fetch_add(1) == 0) {
    // The first: a clean shutdown by the loop that polls the flag; with none polling it, roscpp's
    // shutdown too (ros::requestShutdown only sets roscpp's flag, as roscpp's own handler does).
    if (g_polling_loops.load() == 0) ros::requestShutdown();
    return;
  }
  // The second: the clean shutdown takes too long (a long step, a slow disk). Only async-signal-safe
  // calls here: say so and leave; a bag being written stays "<path>.active" (`rosbag reindex`).
  static const char kMessage[] =
      "cart_sim: second shutdown signal: exiting now (exit 130); an open bag is left as <path>.active\n";
  static_cast<void>(::write(STDERR_FILENO, kMessage, sizeof kMessage - 1));
  ::_exit(kForcedExitCode);
}

}  // namespace

void install_shutdown_signal_handlers() {
  std::signal(SIGINT, on_shutdown_signal);
  std::signal(SIGTERM, on_shutdown_signal);
}

bool shutdown_signal_received() { return g_shutdown_signals.load() > 0; }

SignalsPolled::SignalsPolled() { ++g_polling_loops; }

SignalsPolled::~SignalsPolled() { --g_polling_loops; }

void end_parent_launch(bool wait) {
  const pid_t parent = ::getppid();
  std::string name;
  std::ifstream("/proc/" + std::to_string(parent) + "/comm") >> name;
  if (name != "roslaunch") return;
  ::kill(parent, SIGINT);
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (wait && !shutdown_signal_received() && std::chrono::steady_clock::now() < give_up) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

}  // namespace birkhoff_cart
