#include "birkhoff_cart/core/scene/step_schedule.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace birkhoff_cart {
namespace {

constexpr double kCommensurabilityTolerance = 1e-9;  // relative, for "interval is a multiple of h" [-]

/// The spacing of doubles at |t| [s].
double ulp_at(double t) {
  const double magnitude = std::abs(t);
  return std::nextafter(magnitude, std::numeric_limits<double>::infinity()) - magnitude;
}

std::string text(double value) {
  std::ostringstream stream;
  stream.precision(17);
  stream << value;
  return stream.str();
}

}  // namespace

StepSchedule plan_steps(double start_time, double duration, double step_size) {
  if (!std::isfinite(start_time)) {
    throw TimeLimitError("initial_state.time", "the start time must be finite, got " + text(start_time) + " s");
  }
  if (!std::isfinite(step_size) || !(step_size > 0.0)) {
    throw TimeLimitError("integrator.step_size", "the step size must be finite and > 0 s, got " + text(step_size));
  }
  if (!std::isfinite(duration) || !(duration > 0.0)) {
    throw TimeLimitError("duration", "the duration must be finite and > 0 s, got " + text(duration));
  }
  if (duration < kMinFinalStepFraction * step_size) {
    throw TimeLimitError("duration", "the duration " + text(duration) + " s is shorter than " +
                                         text(kMinFinalStepFraction) + " of the step h = " + text(step_size) +
                                         " s: no step resolves it; use a smaller step");
  }
  const double end_time = start_time + duration;  // t_end [s]
  if (!std::isfinite(end_time)) {
    throw TimeLimitError("duration", "t0 + duration overflows (t0 = " + text(start_time) + " s, duration = " +
                                         text(duration) + " s)");
  }
  // Time resolution: t + h must move t by h to ~1e-6 of a step, at the start and at the end.
  const double finest_step = kTimeResolution * step_size;  // [s]
  for (const double t : {start_time, end_time}) {
    if (ulp_at(t) > finest_step) {
      const bool at_start = t == start_time;
      throw TimeLimitError(
          at_start ? "initial_state.time" : "duration",
          std::string(at_start ? "the start time" : "the end time t0 + duration") + " t = " + text(t) +
              " s is too far from 0 for the step h = " + text(step_size) + " s: doubles there are " + text(ulp_at(t)) +
              " s apart, coarser than 2^-20 h = " + text(finest_step) +
              " s, so step times would round (at worst t + h = t); shorten the run, move it nearer t = 0 or use a "
              "step of at least " + text(ulp_at(t) / kTimeResolution) + " s");
    }
  }
  const double steps = duration / step_size;  // [-]
  if (!(steps < static_cast<double>(kMaxStepCount))) {
    throw TimeLimitError("duration", "the run needs " + text(steps) + " steps of h = " + text(step_size) +
                                         " s, more than the limit 2^53");
  }

  StepSchedule schedule;
  schedule.start_time = start_time;
  schedule.end_time = end_time;
  schedule.step_size = step_size;
  // N: the largest n with tₙ ≤ t_end, starting from ⌊T/h⌋ and corrected for rounding of tₙ.
  std::uint64_t n = static_cast<std::uint64_t>(std::floor(steps));
  while (n > 0 && schedule.grid_time(n) > end_time) --n;
  while (schedule.grid_time(n + 1) <= end_time) ++n;
  const double remainder = end_time - schedule.grid_time(n);  // [s], ≥ 0
  if (remainder > 0.0) {
    schedule.final_step = true;
    // No sliver: merge a final step shorter than kMinFinalStepFraction·h into the step before it.
    if (remainder < kMinFinalStepFraction * step_size && n > 0) --n;
  }
  schedule.whole_steps = n;
  return schedule;
}

void check_times_within(double start_time, double end_time, double earliest, double latest, const std::string& clock) {
  const std::string range = "[" + text(earliest) + ", " + text(latest) + "] s";
  if (!(start_time >= earliest && start_time <= latest)) {
    throw TimeLimitError("initial_state.time", "the start time " + text(start_time) + " s is outside " + clock +
                                                   "'s range " + range);
  }
  if (!(end_time >= earliest && end_time <= latest)) {
    throw TimeLimitError("duration", "the end time " + text(end_time) + " s is outside " + clock + "'s range " + range);
  }
}

std::uint64_t steps_per_interval(double interval, double step_size) {
  const double ratio = interval / step_size;  // [-]
  const std::string numbers = "the interval " + text(interval) + " s is not a whole number of steps of " +
                              text(step_size) + " s (ratio " + text(ratio) + ")";
  if (!std::isfinite(ratio) || !(ratio >= 0.5) || !(ratio <= static_cast<double>(kMaxStepCount))) {
    throw std::invalid_argument(numbers);
  }
  const double whole = std::round(ratio);
  if (std::abs(ratio - whole) > kCommensurabilityTolerance * ratio) throw std::invalid_argument(numbers);
  return static_cast<std::uint64_t>(whole);
}

}  // namespace birkhoff_cart
