// Signal handling without roscpp's: SIGINT and SIGTERM request a clean shutdown (cart_sim closes its
// bag before it exits).
#pragma once

namespace birkhoff_cart {

/// Installs the SIGINT/SIGTERM handlers. Call once after ros::init(..., NoSigintHandler).
void install_shutdown_signal_handlers();
/// True once SIGINT/SIGTERM arrived.
bool shutdown_signal_received();

}  // namespace birkhoff_cart
