// RunWorkMeter (run_work_meter.h).
#include "birkhoff_cart/core/node_logic/run_work_meter.h"

namespace birkhoff_cart {

void RunWorkMeter::start(Clock::time_point now, double scene_time) {
  start_ = now;
  last_progress_wall_ = now;
  last_progress_time_ = scene_time;
}

void RunWorkMeter::count_step(double advanced) {
  ++period_steps_;
  ++steps_;
  simulated_ += advanced;
}

void RunWorkMeter::add_stepping(double seconds) {
  stepping_ += seconds;
  period_stepping_ += seconds;
}

void RunWorkMeter::add_paused(double seconds) { paused_ += seconds; }

double RunWorkMeter::end_period() {
  last_per_step_ = period_steps_ > 0 ? period_stepping_ / static_cast<double>(period_steps_) : 0.0;
  period_stepping_ = 0.0;
  period_steps_ = 0;
  ++instants_;
  return last_per_step_;
}

double RunWorkMeter::wall_time(Clock::time_point now) const {
  return std::chrono::duration<double>(now - start_).count();
}

double RunWorkMeter::real_time_factor(Clock::time_point now) const {
  const double running = wall_time(now) - paused_;
  return running > 0.0 ? simulated_ / running : 0.0;
}

std::optional<double> RunWorkMeter::progress(Clock::time_point now, double scene_time, double period) {
  const double elapsed = std::chrono::duration<double>(now - last_progress_wall_).count();  // [s]
  if (elapsed < period) return std::nullopt;
  const double rate = (scene_time - last_progress_time_) / elapsed;
  last_progress_wall_ = now;
  last_progress_time_ = scene_time;
  return rate;
}

}  // namespace birkhoff_cart
