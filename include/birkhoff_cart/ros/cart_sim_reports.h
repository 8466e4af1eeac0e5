// cart_sim's reports (docs/ros_interface.md, "/diagnostics" and "The summary"): the /diagnostics
// status "simulation" (its level the accuracy guard's, raised by rejected commands and a failed
// step), the fast mode's progress line, and the run's summary paragraph (log and ~summary_path).
// They only read the running node, through a RunView. Part of CartSimNode.
#pragma once

#include <atomic>
#include <cstdint>
#include <optional>
#include <string>

#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/ros.h>

#include "birkhoff_cart/core/scene/accuracy_guard.h"
#include "birkhoff_cart/core/physics/sensors/odometry_sensor.h"
#include "birkhoff_cart/core/run/simulation.h"
#include "birkhoff_cart/ros/cart_sim_parameters.h"
#include "birkhoff_cart/ros/command_inputs.h"
#include "birkhoff_cart/ros/run_record.h"
#include "birkhoff_cart/core/node_logic/run_timeline.h"
#include "birkhoff_cart/core/node_logic/run_work_meter.h"

namespace birkhoff_cart {

/// What the reports read of the running node: references to its parts, which outlive the reports.
struct RunView {
  const CartSimParameters& parameters;
  const Simulation& simulation;
  const AccuracyGuard& guard;
  RunWorkMeter& work;  ///< non-const: the progress lines keep their last reading there
  const CommandInputs& commands;
  const std::optional<RunRecord>& record;
  const std::optional<OdometrySensor>& odometry_sensor;
  const std::atomic<bool>& paused;
  const std::optional<std::string>& step_failure;
  const std::uint64_t& lockstep_timeouts;  ///< lockstep instants that went on without every answer
  const RunTimeline& timeline;             ///< where the run started and stops
};

class CartSimReports {
 public:
  /// /diagnostics through a diagnostic_updater on `node` (its parameters under `private_node`).
  CartSimReports(const RunView& run, ros::NodeHandle& node, ros::NodeHandle& private_node);

  /// The node's start line: scene, integrator and step, mode, publish rate, end, frames, clock, bag.
  void log_start() const;
  /// Publishes the /diagnostics status now (the node calls it every ~diagnostic_period of scene
  /// time); builds it only when someone subscribes.
  void publish_diagnostics();
  /// Fast mode: at most once per second of wall time, one log line with the scene time, the percent
  /// of the run done and the real-time factor since the last line.
  void report_progress();
  /// The error lines of a run stopped by a failed step (with its /diagnostics) or by an unexpected
  /// `internal_error`; returns the outcome then ("step failure: ...", "internal error: ...";
  /// `outcome` when neither).
  std::string report_stop(const std::string& outcome, const std::optional<std::string>& internal_error);
  /// The summary paragraph of a run that ended with `outcome` ("finished", "step failure: ...").
  void write_summary(const std::string& outcome);
  /// Someone subscribes to /diagnostics.
  bool diagnostics_listened() const { return diagnostics_listeners_.getNumSubscribers() > 0; }

 private:
  void produce_diagnostics(diagnostic_updater::DiagnosticStatusWrapper& status);

  RunView run_;
  diagnostic_updater::Updater updater_;
  /// A second handle on the updater's /diagnostics (same topic, same publication in this process),
  /// which never publishes: the updater does not tell its subscribers.
  ros::Publisher diagnostics_listeners_;
  std::uint64_t rejections_seen_ = 0;  ///< rejected commands already reported
};

}  // namespace birkhoff_cart
