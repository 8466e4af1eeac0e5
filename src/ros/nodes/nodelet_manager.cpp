// nodelet_manager: a nodelet manager (nodelet::Loader with its load_nodelet, unload_nodelet and list
// services, as `rosrun nodelet nodelet manager`) that unloads its nodelets before roscpp shuts down
// (docs/ros_interface.md, "Nodelets"). nodelet's own manager lets a SIGINT shut roscpp down first,
// its log output with it, and destroys the nodelets after: cart_sim's summary, written as its
// nodelet ends, was lost. Here the first SIGINT/SIGTERM ends the wait, every nodelet is unloaded
// while roscpp runs (each ends as at its own unload: cart_sim writes its summary and closes its
// bag), and only then does roscpp shut down (`rosnode kill` shuts roscpp down first itself, as it
// does in nodelet's manager).
// nodelet's manager also destroys a loader's bond still open at its exit after its nodelets and
// its callback queues, and the bond's "broken" callback then unloads the nodelet from that
// destroyed state (boost::lock_error, abort: lockstep.launch aborted so when roslaunch stopped the
// loaders and the manager at once). Here no nodelet is left for such a callback, and
// lockstep.launch loads without bonds (`nodelet load ... --no-bond`) besides.
// Exit codes: 0 shut down, 2 refused at start (bad name or remapping), 4 unexpected error,
// 130 a second SIGINT/SIGTERM.
#include <nodelet/loader.h>
#include <ros/callback_queue.h>
#include <ros/ros.h>

#include "birkhoff_cart/core/support/version.h"
#include "birkhoff_cart/ros/node_main.h"
#include "birkhoff_cart/ros/shutdown_signals.h"

namespace {

constexpr double kServicePeriod = 0.1;  // [s of wall time]: the longest wait between looks at the signal flag

}  // namespace

int main(int argc, char** argv) {
  if (birkhoff_cart::print_version_if_asked(argc, argv, "nodelet_manager")) return 0;
  return birkhoff_cart::run_node_main("nodelet_manager", [&] {
    ros::init(argc, argv, "nodelet_manager", ros::init_options::NoSigintHandler);
    birkhoff_cart::install_shutdown_signal_handlers();
    nodelet::Loader loader;  // advertises ~load_nodelet, ~unload_nodelet, ~list; reads ~num_worker_threads
    {
      // The manager's services (load, unload, list) on this thread, as ros::spin() serves them in
      // nodelet's manager; the nodelets' callbacks run on the loader's worker threads.
      const birkhoff_cart::SignalsPolled polled;
      while (!birkhoff_cart::shutdown_signal_received() && ros::ok()) {
        ros::getGlobalCallbackQueue()->callAvailable(ros::WallDuration(kServicePeriod));
      }
    }
    loader.clear();  // every nodelet ends while roscpp still runs
    ros::shutdown();
    return 0;
  });
}
