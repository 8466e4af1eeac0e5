// RunTimeline (run_timeline.h).
#include "birkhoff_cart/core/node_logic/run_timeline.h"

#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>
#include <utility>

#include "birkhoff_cart/core/scene/step_schedule.h"

namespace birkhoff_cart {
namespace {

/// `value` [s] with 10 significant digits, as cart_sim's log lines write times.
std::string seconds(double value) {
  std::ostringstream text;
  text << std::setprecision(10) << value;
  return text.str();
}

/// Instants that round-off puts a hair below a whole multiple still count as reached [-].
constexpr double kInstantRounding = 1e-9;

}  // namespace

RunTimeline::RunTimeline(double duration_parameter, double scene_duration, double step_size, std::string scene_path,
                         double start_time)
    : duration_parameter_(duration_parameter), step_size_(step_size), scene_path_(std::move(scene_path)) {
  if (duration_parameter_ < 0.0) {
    duration_ = scene_duration;
  } else if (duration_parameter_ == 0.0 || std::isinf(duration_parameter_)) {
    duration_ = std::numeric_limits<double>::infinity();
  } else {
    duration_ = duration_parameter_;
  }
  start_at(start_time);
}

std::string RunTimeline::refusal_to_start_at(double start_time) const {
  RunTimeline moved = *this;
  try {
    moved.start_at(start_time);
  } catch (const RunTimelineError& error) {
    return error.what();
  }
  return "";
}

void RunTimeline::start_at(double start_time) {
  // Scene time t is ROS time t, and ROS time cannot be negative: refused here, not at the first
  // /clock (which would end the run in std::terminate with the bag left unfinished).
  if (!(start_time >= 0.0)) {
    throw RunTimelineError("scene " + scene_path_ + " starts at t = " + seconds(start_time) +
                           " s: cart_sim publishes scene time as ROS time, which must be >= 0");
  }
  double end_time = std::numeric_limits<double>::infinity();
  if (std::isfinite(duration_)) {
    try {
      end_time = plan_steps(start_time, duration_, step_size_).end_time;  // cart_simulate's plan
    } catch (const TimeLimitError& error) {
      const bool from_parameter = duration_parameter_ > 0.0 && error.key() == "duration";
      const std::string key = from_parameter ? std::string("~duration") : "scene key '" + error.key() + "'";
      throw RunTimelineError("the run of scene " + scene_path_ + " cannot be cut into steps: " + key + ": " +
                             error.problem());
    }
  }
  // ros::Time holds 32-bit seconds: a stamp at or past 2^32 s throws in roscpp.
  if (!(start_time < kLatestRosTime) || (std::isfinite(end_time) && !(end_time < kLatestRosTime))) {
    throw RunTimelineError("scene " + scene_path_ + " runs from t = " + seconds(start_time) + " s to t = " +
                           seconds(end_time) +
                           " s: cart_sim publishes scene time as ROS time, which ends before 2^32 s = " +
                           seconds(kLatestRosTime) + " s");
  }
  start_time_ = start_time;
  end_time_ = end_time;
}

double RunTimeline::length_from(double time, bool whole_run) const {
  if (whole_run || !std::isfinite(end_time_)) return duration_;
  return end_time_ - time;
}

double start_on_leader_clock(double scene_start, double leader_time, double publish_period,
                             double longest_catch_up) {
  if (!(leader_time - scene_start > longest_catch_up)) return scene_start;
  const double instants = std::floor((leader_time - scene_start) / publish_period + kInstantRounding);
  return scene_start + instants * publish_period;
}

double pacing_factor(bool fast, double real_time_factor, bool follow_clock) {
  if (follow_clock) return 0.0;  // the leader's /clock is the pace
  if (!fast && real_time_factor == 0.0) return 1.0;
  return real_time_factor;
}

}  // namespace birkhoff_cart
