// One run of any Birkhoffian system (birkhoffian_system.h) by a Birkhoffian member of the registry,
// at fixed steps or under a step control, from t₀ to t₁, with the states on the member's own steps:
// the loop a user's system needs (the cart has its own, run/simulation.h). docs/python.md, "Your own
// Birkhoffian system"; the Python module's simulator.integrate is this function on a system whose
// functions are Python callables (src/python/python_system.h).
//
//  - fixed: N = ⌈(t₁ − t₀)/h − 10⁻⁹⌉ steps of h, the last one shortened to land on t₁;
//  - adaptive: the error-per-step control (adaptive_step_control.h) aimed at τ = tolerance/(t₁ − t₀)
//    [1/s] in ê's weights (error_estimate.h), so that the estimates sum to at most the tolerance;
//    its accepted steps. Not the cart's calibrated aim τ_a (tolerance_proportionality.h, eq.
//    (B.53)): measured on the cart's scenes, it ended 5.7x beyond a 1e-4 tolerance on the quartic
//    oscillator of docs/python.md over 100 s, whose phase error grows along the run;
//  - reversible: the reversible control (reversible_step_control.h) for the tolerance, its grid up to
//    the last point before t₁, then one step of the member from that point to t₁ (the grid itself
//    passes t₁; the landing step is not part of it). Every Birkhoffian member (all symmetric); needs
//    the identity chart (time enters the time transformation as a passive coordinate).
//
// Events g(t, z) = 0 (as scipy's solve_ivp: a direction, terminal or not) are watched on every step:
// where g changes sign over a step [tₐ, t_b], the crossing is located (crossing.h: Illinois,
// safeguarded by bisection) on the member's own step from (tₐ, zₐ) to τ, to a bracket of
// 10⁻¹³·max(1 s, |t_b|): the state there is the member's state, not an interpolant's. A terminal event ends the run there (the last state is the event's).
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <algorithm>
#include <type_traits>
#include <vector>

#include "birkhoff_cart/core/integrators/adaptive_step_control.h"
#include "birkhoff_cart/core/integrators/birkhoffian_system.h"
#include "birkhoff_cart/core/integrators/carried_point.h"
#include "birkhoff_cart/core/integrators/crossing.h"
#include "birkhoff_cart/core/integrators/diagnostics.h"
#include "birkhoff_cart/core/integrators/integrator_kind.h"
#include "birkhoff_cart/core/integrators/integrator_members.h"
#include "birkhoff_cart/core/integrators/integrator_settings.h"
#include "birkhoff_cart/core/integrators/reversible_step_control.h"
#include "birkhoff_cart/core/integrators/step_error.h"
#include "birkhoff_cart/core/integrators/system_traits.h"
#include "birkhoff_cart/core/integrators/time_transformed_system.h"

namespace birkhoff_cart {

/// How the steps of a system run are chosen.
enum class SystemStepControl { kFixed, kAdaptive, kReversible };

/// What a system run asks for.
struct SystemRunRequest {
  std::string integrator = "birkhoff_gauss8";  ///< a Birkhoffian member of the registry
  SystemStepControl control = SystemStepControl::kFixed;
  double step_size = 0.0;  ///< fixed: h [s] > 0; adaptive: the first attempt (0: (t₁ − t₀)/100) [s]
  double tolerance = 0.0;  ///< the step controls: the error at t₁ in ê's weights [-] > 0
  std::uint64_t max_steps = 1000000;  ///< work limit: steps (accepted or not) before the run ends by name
};

/// An event function g(t, z) [any unit] whose zeros are watched (scipy's solve_ivp events).
template <class System>
struct SystemEvent {
  std::function<double(double, const StateVector<System, double>&)> function;
  int direction = 0;      ///< +1: only where g rises through 0, −1: only where it falls, 0: both
  bool terminal = false;  ///< the run ends at its first crossing
};

/// A located crossing of event `event` (its index) at `time` [s] in state `state`.
template <class System>
struct SystemEventCrossing {
  std::size_t event = 0;
  double time = 0.0;
  StateVector<System, double> state;
};

/// A run's result: the states on the member's own steps, t₀ first and t₁ (or a terminal event) last.
template <class System>
struct SystemRunResult {
  std::vector<double> times;                            ///< [s]
  std::vector<StateVector<System, double>> states;      ///< z at times [the system's units]
  std::vector<SystemEventCrossing<System>> crossings;   ///< the events' crossings, in time order
  StepStatistics statistics;                            ///< evaluations, steps, rejected attempts
  bool finished = false;        ///< reached t₁ or a terminal event
  bool terminal_event = false;  ///< ended at a terminal event
  std::string message;          ///< why it stopped
};

/// A carried point of `System` at z [its units], y = 0, its angles reduced: where a run starts.
template <class System, class Memory>
CarriedPoint<System, Memory> seeded_point(const System& system, const StateVector<System, double>& z) {
  CarriedPoint<System, Memory> point;
  point.point.z = z;
  point.periodic_angles = system_traits::periodic_angles(system);
  point.reduce_angles();
  point.valid = true;
  return point;
}

namespace system_integration_detail {

/// The Gauss members with two stages or more: the ones the step controls take here (their estimate
/// is of order s + 2; birkhoff2's and the compositions' are refused under the adaptive control,
/// integrator_members.h).
template <class Stepper>
struct IsGaussMember : std::false_type {};
template <int Stages>
struct IsGaussMember<GaussCollocation<Stages>> : std::integral_constant<bool, (Stages >= 2)> {};
template <class Stepper>
constexpr bool kIsGaussMember = IsGaussMember<Stepper>::value;


/// z of a carried point with its turns put back and its remainder added [the system's units].
template <class System, class Point>
StateVector<System, double> unreduced(const Point& carried) {
  StateVector<System, double> z = carried.point.z.template head<System::kDimension>() +
                                  carried.point.z_remainder.template head<System::kDimension>();
  constexpr auto angles = system_traits::kAngleCoordinates<System>;
  for (std::size_t k = 0; k < angles.size(); ++k) {
    if (!angles[k].passive) z(angles[k].index) += 2.0 * M_PI * carried.turns[k];
  }
  return z;
}

/// Thrown out of a control's loop when a terminal event ends the run.
struct TerminalEventReached {};

/// Watches the events over each new step of a run and locates their crossings (file comment).
/// `side_step(tₐ, zₐ, τ)`: the member's state at τ by one step from (tₐ, zₐ).
template <class System, class SideStep>
class EventWatch {
 public:
  using Z = StateVector<System, double>;
  EventWatch(const std::vector<SystemEvent<System>>& events, SideStep side_step, SystemRunResult<System>& result)
      : events_(events), side_step_(std::move(side_step)), result_(result) {
    for (const SystemEvent<System>& event : events_) values_.push_back(value(event, result.times.back(), result.states.back()));
  }

  /// Records the step's end (t, z) in the result, after the crossings inside the step; a terminal one
  /// replaces the end by itself and returns true.
  bool record(double t, const Z& z) {
    const double t_start = result_.times.back();
    const Z z_start = result_.states.back();
    std::vector<SystemEventCrossing<System>> found;
    std::vector<double> values(events_.size());
    for (std::size_t k = 0; k < events_.size(); ++k) {
      values[k] = value(events_[k], t, z);
      const double before = values_[k];
      const double after = values[k];
      const bool rises = before < 0.0 && after >= 0.0;
      const bool falls = before > 0.0 && after <= 0.0;
      if (!((rises && events_[k].direction >= 0) || (falls && events_[k].direction <= 0))) continue;
      found.push_back(locate(k, t_start, z_start, before, t, z, after));
    }
    values_ = values;
    std::sort(found.begin(), found.end(), [](const auto& a, const auto& b) { return a.time < b.time; });
    for (const SystemEventCrossing<System>& crossing : found) {
      result_.crossings.push_back(crossing);
      if (events_[crossing.event].terminal) {
        result_.times.push_back(crossing.time);
        result_.states.push_back(crossing.state);
        result_.terminal_event = true;
        std::ostringstream message;
        message << "terminal event " << crossing.event << " at t = " << crossing.time << " s";
        result_.message = message.str();
        return true;
      }
    }
    result_.times.push_back(t);
    result_.states.push_back(z);
    return false;
  }

 private:
  double value(const SystemEvent<System>& event, double t, const Z& z) const {
    const double g = event.function(t, z);
    if (std::isnan(g)) {
      std::ostringstream message;
      message << "an event function returned NaN at t = " << t << " s";
      throw std::invalid_argument(message.str());
    }
    return g;
  }

  /// The crossing in τ ∈ [tₐ, t_b] (locate_crossing: Illinois, safeguarded by bisection), g read on the
  /// member's state at τ by one step from (tₐ, zₐ).
  SystemEventCrossing<System> locate(std::size_t k, double ta, const Z& za, double ga, double tb, const Z& zb,
                                     double gb) {
    SystemEventCrossing<System> crossing{k, tb, zb};
    if (gb == 0.0) return crossing;
    const auto g = [&](double tau) { return value(events_[k], tau, side_step_(ta, za, tau)); };
    const Crossing found = locate_crossing(g, ta, ga, tb, gb, 1e-13 * std::max(1.0, std::abs(tb)));
    crossing.time = found.time;
    crossing.state = found.time == tb ? zb : side_step_(ta, za, found.time);
    return crossing;
  }

  const std::vector<SystemEvent<System>>& events_;
  SideStep side_step_;
  SystemRunResult<System>& result_;
  std::vector<double> values_;  ///< g of each event at the last recorded state
};

template <class Stepper, class System, class Watch>
void run_fixed(const Stepper& stepper, System& system, double t0, double t1, const SystemRunRequest& request,
               SystemRunResult<System>& result, Watch& watch) {
  const double h = request.step_size;
  if (!(h > 0.0) || !std::isfinite(h)) throw std::invalid_argument("step_size must be finite and > 0 s at fixed steps");
  const double span = t1 - t0;
  const double count = std::ceil(span / h - 1e-9);
  if (count > static_cast<double>(request.max_steps)) {
    std::ostringstream message;
    message << "step_size " << h << " s needs " << count << " steps over " << span << " s, beyond max_steps "
            << request.max_steps;
    throw std::invalid_argument(message.str());
  }
  const auto steps = static_cast<std::uint64_t>(count);
  auto point = seeded_point<System, typename Stepper::template Memory<System>>(system, result.states.front());
  for (std::uint64_t n = 1; n <= steps; ++n) {
    const double t = t0 + static_cast<double>(n - 1) * h;
    const double t_next = n == steps ? t1 : t0 + static_cast<double>(n) * h;
    system_traits::begin_step(system, t);
    stepper.advance_compensated(system, point.point, point.memory, t, t_next - t, result.statistics);
    point.reduce_angles();
    ++result.statistics.internal_steps;
    if (watch.record(t_next, unreduced<System>(point))) return;
  }
}

template <class Stepper, class System, class Watch>
void run_adaptive(const Stepper& stepper, System& system, double t0, double t1, const SystemRunRequest& request,
                  SystemRunResult<System>& result, Watch& watch) {
  using Carried = CarriedPoint<System, typename Stepper::template Memory<System>>;
  AdaptiveStepSettings settings;
  settings.error_per_unit_step = request.tolerance / (t1 - t0);
  settings.max_steps_per_advance = request.max_steps;
  AdaptiveStepControl<Stepper, System, Carried> control(stepper, settings);
  const double first = request.step_size > 0.0 ? request.step_size : (t1 - t0) / 100.0;
  control.start(seeded_point<System, typename Stepper::template Memory<System>>(system, result.states.front()), t0, first);
  while (control.time() < t1) {
    if (result.statistics.internal_steps + result.statistics.rejected_steps >= request.max_steps) {
      std::ostringstream message;
      message << "the adaptive control took max_steps = " << request.max_steps << " steps and attempts before t = "
              << t1 << " s (at t = " << control.time() << " s)";
      throw StepError(message.str());
    }
    control.step(system, t1, result.statistics);
    if (watch.record(control.time(), unreduced<System>(control.grid()))) return;
  }
}

template <class Stepper, class System, class Watch>
void run_reversible(const Stepper& stepper, const System& system, double t0, double t1,
                    const SystemRunRequest& request, SystemRunResult<System>& result, Watch& watch) {
  using Control = ReversibleToleranceControl<Stepper, System>;
  typename Control::Transformed transformed{system, t0};
  Control control{stepper, transformed, request.tolerance / (t1 - t0), t1 - t0};
  const auto start = seeded_point<System, NoStepMemory>(system, result.states.front());
  control.calibrate(start, t0, result.statistics);
  control.start(start, t0);
  try {
    control.advance_past(t1, result.statistics, [&] {
      if (result.times.size() >= request.max_steps) {
        std::ostringstream message;
        message << "the reversible control's grid reached max_steps = " << request.max_steps
                << " points before t = " << t1 << " s";
        throw StepError(message.str());
      }
      if (control.time() < t1 && watch.record(control.time(), unreduced<System>(control.grid()))) {
        throw TerminalEventReached{};
      }
    });
  } catch (const TerminalEventReached&) {
    return;
  }
  // Land on t₁ with one step of the member from the last grid point before it (or on it).
  const double t_last = result.times.back();
  if (t_last < t1) {
    StateVector<System, double> z = result.states.back();
    PassiveVector<System, double> y = PassiveVector<System, double>::Zero();
    stepper.step(system, z, y, t_last, t1 - t_last, result.statistics);
    watch.record(t1, z);
  }
}

}  // namespace system_integration_detail

/// Is `name` a Birkhoffian member, and which controls does it take here?
struct SystemMemberInfo {
  bool found = false;
  bool adaptive = false;    ///< the Gauss members with two stages or more (the registry's)
  bool reversible = false;  ///< every (symmetric) Birkhoffian member, where the system's chart is the identity
};

template <class System>
SystemMemberInfo system_member_info(const std::string& name) {
  SystemMemberInfo info;
  std::apply(
      [&](const auto&... member) {
        (
            [&](const auto& m) {
              using Stepper = typename std::decay_t<decltype(m)>::Type;
              if constexpr (is_birkhoffian(member_kind<Stepper>())) {
                if (name == Stepper::name()) {
                  info.found = true;
                  info.adaptive = system_integration_detail::kIsGaussMember<Stepper>;
                  info.reversible = Stepper::kSymmetric && system_traits::kDarbouxChartIsIdentity<System>;
                }
              }
            }(member),
            ...);
      },
      kIntegratorMembers);
  return info;
}

/// The Birkhoffian members' names, in the registry's order.
inline std::vector<std::string> birkhoffian_member_names() {
  std::vector<std::string> names;
  std::apply(
      [&](const auto&... member) {
        (
            [&](const auto& m) {
              using Stepper = typename std::decay_t<decltype(m)>::Type;
              if constexpr (is_birkhoffian(member_kind<Stepper>())) names.emplace_back(Stepper::name());
            }(member),
            ...);
      },
      kIntegratorMembers);
  return names;
}

/// Integrates `system` from z₀ at t₀ [s] to t₁ [s] > t₀ as `request` says. Bad requests (an unknown
/// or non-Birkhoffian member, a control the member does not take here, a step or tolerance that is
/// not finite and positive) throw std::invalid_argument naming them. A step that fails for good
/// (StepError: a stage solve at fixed steps, the controls' work limits and step floors) ends the run
/// with `finished` false and its message; the states before it are kept. Anything else the system's
/// functions throw passes through. `events`: watched on every step (file comment); an event function
/// that returns NaN is std::invalid_argument.
template <class System>
SystemRunResult<System> integrate_system(System& system, const StateVector<System, double>& z0, double t0, double t1,
                                         const SystemRunRequest& request,
                                         const std::vector<SystemEvent<System>>& events = {}) {
  if (!std::isfinite(t0) || !std::isfinite(t1) || !(t1 > t0)) {
    throw std::invalid_argument("the time span needs finite t0 < t1 [s]");
  }
  if (!z0.allFinite()) throw std::invalid_argument("the initial state z0 holds a value that is not finite");
  const SystemMemberInfo info = system_member_info<System>(request.integrator);
  if (!info.found) {
    std::ostringstream message;
    message << "integrator '" << request.integrator << "' is not a Birkhoffian member; take one of:";
    for (const std::string& name : birkhoffian_member_names()) message << " " << name;
    throw std::invalid_argument(message.str());
  }
  if (request.control != SystemStepControl::kFixed) {
    if (!(request.tolerance > 0.0) || !std::isfinite(request.tolerance)) {
      throw std::invalid_argument("a step control needs a finite tolerance > 0");
    }
    const bool taken = request.control == SystemStepControl::kAdaptive ? info.adaptive : info.reversible;
    if (!taken) {
      std::ostringstream message;
      if (request.control == SystemStepControl::kAdaptive) {
        message << "step control 'adaptive' is not for '" << request.integrator
                << "': it takes birkhoff_gauss4, birkhoff_gauss6 and birkhoff_gauss8 (the others' estimates do "
                   "not follow their error: docs/accuracy.md §4.4); run it at fixed steps";
      } else {
        message << "step control 'reversible' is not for this system: it needs the identity chart (a system "
                   "without a Darboux chart of its own); run it at fixed steps or under the adaptive control";
      }
      throw std::invalid_argument(message.str());
    }
  }
  SystemRunResult<System> result;
  std::apply(
      [&](const auto&... member) {
        (
            [&](const auto& m) {
              using Stepper = typename std::decay_t<decltype(m)>::Type;
              if constexpr (is_birkhoffian(member_kind<Stepper>())) {
                if (request.integrator != Stepper::name()) return;
                const Stepper stepper = configured_stepper<Stepper>(IntegratorSettings{});
                // The member's state at τ by one step from (tₐ, zₐ): where the events are located.
                auto side_step = [&](double ta, const StateVector<System, double>& za, double tau) {
                  StateVector<System, double> z = za;
                  PassiveVector<System, double> y = PassiveVector<System, double>::Zero();
                  stepper.step(system, z, y, ta, tau - ta, result.statistics);
                  return z;
                };
                result.times.clear();
                result.states.clear();
                result.times.push_back(t0);
                result.states.push_back(z0);
                system_integration_detail::EventWatch<System, decltype(side_step)> watch(events, side_step, result);
                try {
                  if (request.control == SystemStepControl::kFixed) {
                    system_integration_detail::run_fixed(stepper, system, t0, t1, request, result, watch);
                  }
                  if constexpr (system_integration_detail::kIsGaussMember<Stepper>) {
                    if (request.control == SystemStepControl::kAdaptive) {
                      system_integration_detail::run_adaptive(stepper, system, t0, t1, request, result, watch);
                    }
                  }
                  if constexpr (Stepper::kSymmetric && system_traits::kDarbouxChartIsIdentity<System>) {
                    if (request.control == SystemStepControl::kReversible) {
                      system_integration_detail::run_reversible(stepper, system, t0, t1, request, result, watch);
                    }
                  }
                  result.finished = true;
                  if (!result.terminal_event) result.message = "the run reached t1";
                } catch (const StepError& error) {
                  result.finished = false;
                  result.message = error.what();
                }
              }
            }(member),
            ...);
      },
      kIntegratorMembers);
  return result;
}

}  // namespace birkhoff_cart
