// SIGINT/SIGTERM as a shutdown request (see shutdown_signals.h).
#include "birkhoff_cart/ros/shutdown_signals.h"

#include <atomic>
#include <csignal>

namespace birkhoff_cart {
namespace {

std::atomic<bool> g_shutdown_signal{false};

extern "C" void on_shutdown_signal(int /*signal*/) { g_shutdown_signal.store(true); }

}  // namespace

void install_shutdown_signal_handlers() {
  std::signal(SIGINT, on_shutdown_signal);
  std::signal(SIGTERM, on_shutdown_signal);
}

bool shutdown_signal_received() { return g_shutdown_signal.load(); }

}  // namespace birkhoff_cart
