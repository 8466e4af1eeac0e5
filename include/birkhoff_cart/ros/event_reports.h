// cart_sim's ~events (docs/events.md): the core's EventLocator on the node's run, each crossing
// published on ~events (birkhoff_cart/CartEvent), logged and written to the bag, and a terminal one
// reported so that the node pauses. It only translates: the crossings come from the core.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <ros/node_handle.h>
#include <ros/publisher.h>

#include "birkhoff_cart/core/run/simulation.h"
#include "birkhoff_cart/core/run/state_events.h"
#include "birkhoff_cart/ros/run_record.h"

namespace birkhoff_cart {

class EventReports {
 public:
  /// The events of `texts` (validated by load_parameters) on `simulation`'s run; with events, a
  /// member with its own steps is watched at each of them (Simulation::observe_grid). Throws
  /// std::invalid_argument when the run's states between steps cannot be had (fixed steps with
  /// actuators or end stops: EventLocator's reason).
  EventReports(ros::NodeHandle& private_node, const std::vector<std::string>& texts, Simulation& simulation,
               const std::string& frame_id);
  ~EventReports();  ///< stops watching the simulation's own steps
  EventReports(const EventReports&) = delete;
  EventReports& operator=(const EventReports&) = delete;

  bool active() const { return !events_.empty(); }
  /// A new run from the simulation's state now (start, ~reset, a teleport): the occurrences count
  /// from 1 again. A locator that cannot start there is logged and the events stay off until the next.
  void restart();
  /// After each step of the run: its crossings (at fixed steps read here, with own steps already
  /// seen by the observer), published and written to `record`. True when a terminal one fell in it
  /// (the locator then starts again from the state now, so that the run can go on).
  bool after_step(RunRecord* record);

 private:
  Simulation& simulation_;
  std::vector<StateEvent> events_;
  std::optional<EventLocator> locator_;
  std::vector<std::size_t> published_;  ///< occurrences of each event already published
  ros::Publisher publisher_;
  std::string frame_id_;
};

}  // namespace birkhoff_cart
