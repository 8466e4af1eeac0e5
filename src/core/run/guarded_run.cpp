// GuardedRun (guarded_run.h): a simulation run to its output instants with its accuracy guard.
#include "birkhoff_cart/core/run/guarded_run.h"

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

#include "birkhoff_cart/core/cart_binding/cart_stepper.h"
#include "birkhoff_cart/core/scene/step_schedule.h"

namespace birkhoff_cart {

GuardedRun::GuardedRun(const Scene& scene, OutputInstants instants)
    : simulation_(scene), guard_(scene.accuracy), instants_(instants) {
  try {
    steps_between_checks_ = steps_per_interval(1.0 / scene.output_rate, scene.integrator.step_size);
    checks_at_output_instants_ = true;
  } catch (const std::invalid_argument&) {
    steps_between_checks_ = 1;  // output interval no whole number of steps: check after every step
  }
  check_start();
}

void GuardedRun::require_output_instants_on_steps() const {
  const Scene& scene = simulation_.scene();
  steps_per_interval(1.0 / scene.output_rate, scene.integrator.step_size);
}

void GuardedRun::check_start() {
  if (instants_ == OutputInstants::kOutputRate) check(simulation_.schedule().start_time);
}

void GuardedRun::check(double time) { check(time, simulation_.diagnostics()); }

void GuardedRun::check(double time, const Diagnostics& diagnostics) {
  guard_.check(time, diagnostics, simulation_.statistics());
}

std::optional<double> GuardedRun::step() {
  simulation_.step_on_schedule();
  if (instants_ != OutputInstants::kOutputRate) return std::nullopt;
  // The output instants t₀ + k/rate among the whole steps, and the run's end.
  const StepSchedule& schedule = simulation_.schedule();
  const std::uint64_t n = simulation_.steps_taken();
  std::optional<double> instant;
  if (n <= schedule.whole_steps && n % steps_between_checks_ == 0) {
    const double rate = simulation_.scene().output_rate;  // [Hz]
    instant = checks_at_output_instants_
                  ? schedule.start_time + static_cast<double>(n / steps_between_checks_) / rate
                  : simulation_.state().time;
  } else if (simulation_.at_end()) {
    instant = schedule.end_time;
  }
  if (instant) check(*instant);
  return instant;
}

std::uint64_t GuardedRun::advance(std::uint64_t count, const std::vector<StepCommands>& commands, bool record,
                                  std::vector<CartState>* states) {
  if (!commands.empty() && commands.size() != count) {
    throw std::invalid_argument("per-step commands: " + std::to_string(commands.size()) + " given for " +
                                std::to_string(count) + " steps");
  }
  if (off_grid_ && count > 0) {
    throw std::logic_error("run_to() gave states between " + simulation_.integrator_name() +
                           "'s own steps (its dense output): continue with run_to() or run(), or reset()");
  }
  std::uint64_t taken = 0;
  try {
    for (; taken < count && !simulation_.at_end(); ++taken) {
      if (!commands.empty()) {
        if (!std::isnan(commands[taken].steering)) simulation_.set_steering_command(commands[taken].steering);
        if (!std::isnan(commands[taken].drive)) simulation_.set_drive_command(commands[taken].drive);
      }
      step();
      if (record) states->push_back(simulation_.state());
    }
  } catch (const StepError& error) {
    throw StepError(std::string(error.what()) + " (step " + std::to_string(taken + 1) + " of this call's " +
                    std::to_string(count) + "; the state is the last good step's)");
  }
  return taken;
}

void GuardedRun::run_to_end() {
  if (off_grid_) {
    if (!simulation_.at_end()) states_at({simulation_.end_time()});
    return;
  }
  while (!simulation_.at_end()) step();
}

namespace {

std::string time_text(double time) {
  std::ostringstream text;
  text.precision(17);
  text << "time " << time << " s";
  return text.str();
}

/// Finite and increasing, or std::invalid_argument naming the time.
void require_increasing(const std::vector<double>& times) {
  for (std::size_t j = 0; j < times.size(); ++j) {
    if (!std::isfinite(times[j])) throw std::invalid_argument(time_text(times[j]) + " is not finite");
    if (j > 0 && !(times[j] > times[j - 1])) {
      throw std::invalid_argument("the times must increase: " + time_text(times[j]) + " follows " +
                                  time_text(times[j - 1]));
    }
  }
}

}  // namespace

std::vector<CartState> GuardedRun::states_at(const std::vector<double>& times,
                                             const std::function<void(const Simulation&)>& observe) {
  require_increasing(times);
  return simulation_.takes_own_steps() ? dense_states_at(times, observe) : grid_states_at(times, observe);
}

std::vector<CartState> GuardedRun::dense_states_at(const std::vector<double>& times,
                                                   const std::function<void(const Simulation&)>& observe) {
  const double now = simulation_.state().time;  // [s]
  const double end = simulation_.end_time();     // [s]
  for (double time : times) {
    if (time < now || time > end) {
      std::ostringstream text;
      text.precision(17);
      text << time_text(time) << (time < now ? " is in the past: the run is at t = " : " is beyond the run's end ")
           << (time < now ? now : end) << " s";
      throw std::invalid_argument(text.str());
    }
  }
  std::vector<CartState> states;
  states.reserve(times.size());
  for (double time : times) {
    if (time > simulation_.state().time) {
      simulation_.advance_output_to(time);  // the member's own steps, and its dense output at `time`
      off_grid_ = true;
      check(time);
    }
    states.push_back(simulation_.state());
    if (observe) observe(simulation_);
  }
  return states;
}

std::uint64_t schedule_step_at(const StepSchedule& schedule, double time, const std::string& member) {
  const double h = schedule.step_size;  // [s]
  if (std::abs(time - schedule.end_time) <= kTimeResolution * h) return schedule.total_steps();
  const double steps = std::round((time - schedule.start_time) / h);
  if (!(steps >= 0.0) || steps > static_cast<double>(schedule.whole_steps) ||
      std::abs(schedule.grid_time(static_cast<std::uint64_t>(steps)) - time) > kTimeResolution * h) {
    std::ostringstream text;
    text.precision(17);
    text << time_text(time) << " is not one of the step schedule's instants t0 + n*h (t0 = " << schedule.start_time
         << " s, h = " << h << " s) and its end " << schedule.end_time << " s: " << member
         << " steps at fixed steps, and its states between them are not interpolated (a step control gives any "
            "instant)";
    throw std::invalid_argument(text.str());
  }
  return static_cast<std::uint64_t>(steps);
}

std::vector<CartState> GuardedRun::grid_states_at(const std::vector<double>& times,
                                                  const std::function<void(const Simulation&)>& observe) {
  // The step count at each time, checked before any step is taken.
  std::vector<std::uint64_t> targets;
  for (double time : times) {
    const std::uint64_t n = schedule_step_at(simulation_.schedule(), time, simulation_.integrator_name());
    if (n < simulation_.steps_taken()) {
      std::ostringstream text;
      text.precision(17);
      text << time_text(time) << " is in the past: the run is at t = " << simulation_.state().time << " s";
      throw std::invalid_argument(text.str());
    }
    targets.push_back(n);
  }
  std::vector<CartState> states;
  states.reserve(times.size());
  for (std::uint64_t n : targets) {
    while (simulation_.steps_taken() < n) step();
    states.push_back(simulation_.state());
    if (observe) observe(simulation_);
  }
  return states;
}

void GuardedRun::reset() {
  simulation_.reset();
  off_grid_ = false;
  guard_.reset();
  check_start();
}

}  // namespace birkhoff_cart
