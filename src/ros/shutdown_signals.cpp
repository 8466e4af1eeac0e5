// SIGINT/SIGTERM as a shutdown request (see shutdown_signals.h).
#include "birkhoff_cart/ros/shutdown_signals.h"

#include <unistd.h>

#include <atomic>
#include <csignal>
#include <cstdio>

namespace birkhoff_cart {
namespace {

std::atomic<int> g_shutdown_signals{0};

extern "C" void on_shutdown_signal(int /*signal*/) {
  if (g_shutdown_signals.fetch_add(1) == 0) return;  // the first: a clean shutdown by the time loop
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

}  // namespace birkhoff_cart
