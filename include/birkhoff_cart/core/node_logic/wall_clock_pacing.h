// Real-time pacing by absolute deadlines (ROS-free, unit-tested): scene time t is due at the wall
// instant anchor_wall + (t − anchor_time) / factor. The anchor is set again at the start, at the
// end of a pause and at a reset, so a deadline never refers to a span in which the node did not
// run (before, a reset kept the old deadline: /clock stalled, then fast-forwarded).
#pragma once

#include <algorithm>
#include <chrono>

namespace birkhoff_cart {

class WallClockPacing {
 public:
  using Clock = std::chrono::steady_clock;

  /// `factor` [-]: scene seconds per wall second; 0 = unpaced (as fast as possible).
  explicit WallClockPacing(double factor = 0.0) : factor_(factor) {}

  /// Longest single sleep of cart_sim's waits [s of wall time]: a SIGINT/SIGTERM (whose handler
  /// cannot wake a condition) is seen within this time.
  static constexpr double kLongestSleep = 0.1;
  /// The wall instant `seconds` [s] from now.
  static Clock::time_point after(double seconds) {
    return Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
  }

  bool paced() const { return factor_ > 0.0; }
  double factor() const { return factor_; }

  /// Scene time `scene_time` [s] is due now, at `wall`.
  void restart(Clock::time_point wall, double scene_time) {
    anchor_wall_ = wall;
    anchor_time_ = scene_time;
  }
  /// The wall instant at which scene time `scene_time` [s] is due (paced() only); at most
  /// kFarthestDue after the anchor (a tiny factor would overflow the clock's integer nanoseconds).
  Clock::time_point due(double scene_time) const {
    const double seconds = std::min((scene_time - anchor_time_) / factor_, kFarthestDue);  // [s]
    return anchor_wall_ + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
  }

  /// The farthest a due instant lies after the anchor [s of wall time] (≈ 32 years; int64
  /// nanoseconds reach 292 years).
  static constexpr double kFarthestDue = 1e9;
  /// The scene time [s] due at `wall` (paced() only).
  double scene_time_at(Clock::time_point wall) const {
    return anchor_time_ + factor_ * std::chrono::duration<double>(wall - anchor_wall_).count();
  }

 private:
  double factor_;
  Clock::time_point anchor_wall_{};
  double anchor_time_ = 0.0;  ///< [s]
};

}  // namespace birkhoff_cart
