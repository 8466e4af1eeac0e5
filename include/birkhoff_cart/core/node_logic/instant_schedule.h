// The node's schedules of instants (publishing, diagnostics): start + k·period [s], k = 1, 2, ...
// from the run's (re)start.
#pragma once

#include <cstdint>

namespace birkhoff_cart {

/// One schedule of instants start + k·period [s], k = index, index + 1, ...: advances `index` past
/// every instant at or before `time` + `margin` [s] (half a step, so round-off in t does not move an
/// instant to the next step). True when at least one instant was passed.
inline bool pass_due_instants(double start, double period, double time, double margin, std::uint64_t& index) {
  bool passed = false;
  while (start + static_cast<double>(index) * period <= time + margin) {
    passed = true;
    ++index;
  }
  return passed;
}

/// cart_sim's publish instants start + k·publish_period and /diagnostics instants start +
/// k·diagnostic_period [s], k = 1, 2, ..., from the start of the run in force, and its first /clock.
class PublishSchedule {
 public:
  /// Both periods [s of scene time], > 0.
  PublishSchedule(double publish_period, double diagnostic_period)
      : publish_period_(publish_period), diagnostic_period_(diagnostic_period) {}

  double publish_period() const { return publish_period_; }  ///< [s]
  /// A run (re)starts: the instants count again from its start, and the first /clock is again due.
  void restart() {
    next_publish_ = 1;
    next_diagnostic_ = 1;
    clock_started_ = false;
  }
  /// The next publish instant [s] of the run started at `start` [s].
  double next_instant(double start) const { return start + static_cast<double>(next_publish_) * publish_period_; }
  /// Passes the publish (/diagnostics) instants due at `time` [s] within `margin` [s] (pass_due_instants).
  bool pass_publish_instants(double start, double time, double margin) {
    return pass_due_instants(start, publish_period_, time, margin, next_publish_);
  }
  bool pass_diagnostic_instants(double start, double time, double margin) {
    return pass_due_instants(start, diagnostic_period_, time, margin, next_diagnostic_);
  }
  /// After a step to `time` [s] (half a step `margin` [s]; `at_end`: the run's end): does the first
  /// /clock, t0 + h, go out now? Once per run, unless that step is a publish instant or the end,
  /// which send their own.
  bool first_clock_due(double start, double time, double margin, bool at_end) {
    if (clock_started_) return false;
    clock_started_ = true;
    return !at_end && next_instant(start) > time + margin;
  }

 private:
  double publish_period_;     ///< [s]
  double diagnostic_period_;  ///< [s]
  std::uint64_t next_publish_ = 1;     ///< k of the next publish instant
  std::uint64_t next_diagnostic_ = 1;  ///< k of the next /diagnostics instant
  bool clock_started_ = false;         ///< the first /clock went out
};

}  // namespace birkhoff_cart
