// Events of a cart run: a function g(state) of the cart's state whose zero crossings are recorded,
// and may stop the run, located on the member's own step to a stated time tolerance (docs/events.md).
// One locator for every face: the Python module's solve() (g a Python callable), cart_simulate's
// --event and cart_sim's ~events (g a state field minus a value, state_field_event()).
//
// A crossing inside the step from `before` to `after` is located by locate_crossing (crossing.h) on
//   - the member's dense output of its newest accepted own step (a step control; dopri5), or
//   - states reached by one step of the member from `before` (fixed steps:
//     Simulation::state_by_one_step),
// so the state at a crossing is the member's own, to its order. ROS-free.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "birkhoff_cart/core/integrators/diagnostics.h"
#include "birkhoff_cart/core/physics/state.h"

namespace birkhoff_cart {

class Simulation;

/// One event: g and solve_ivp's attributes, and the crossings found so far.
struct StateEvent {
  std::string name;                                ///< how messages name it ("chi=0.3,rising")
  std::function<double(const CartState&)> g;      ///< its zero is the event; a NaN is refused
  double direction = 0.0;                          ///< > 0: only − to +; < 0: only + to −; 0: both
  std::uint64_t terminal_after = 0;                ///< the run stops at this occurrence (0: never)
  std::vector<double> times;                       ///< the occurrences' times [s]
  std::vector<CartState> states;                   ///< the states there
};

/// The state fields an event of state_field_event() may watch, by the names of the CSV columns and
/// of the Python module's STATE_FIELDS: t, x, y, theta, chi, phi1..phi4, pi1, omega1, omega2 (SI).
const std::vector<std::string>& event_field_names();
/// That field of `state` (std::invalid_argument for another name).
double state_field(const CartState& state, const std::string& field);

/// An event from its text FIELD=VALUE[,rising|falling][,terminal]: g = FIELD − VALUE (VALUE in the
/// field's SI unit), rising (only − to +), falling (only + to −) or both, terminal (the run stops
/// at its first crossing). std::invalid_argument naming the text and what is wrong with it.
StateEvent state_field_event(const std::string& text);

/// The events of several texts, each as state_field_event(); a text given twice is refused by name.
std::vector<StateEvent> state_field_events(const std::vector<std::string>& texts);

/// Finds the events' crossings step by step and stops at a terminal one.
class EventLocator {
 public:
  /// solve()'s and the CLI's default width of the bracket a crossing is located in [s].
  static constexpr double kDefaultTimeTolerance = 1e-12;

  /// For `simulation`'s run (kept by reference; it must outlive the locator) and `events` (kept by
  /// reference: the crossings are appended to them). std::invalid_argument for a tolerance that is
  /// not > 0, and, at fixed steps, for a scene whose states between steps cannot be had
  /// (Simulation::state_by_one_step's reason: actuators or end stops). Reads g at the current state.
  /// `work`: where the locating's evaluations are added (nullptr: the locator's own, work()).
  EventLocator(const Simulation& simulation, std::vector<StateEvent>& events,
               double time_tolerance = kDefaultTimeTolerance, StepStatistics* work = nullptr);

  /// The run went on from the state of the last call (or of the construction) to `after`: the
  /// member's newest own step, or a step of the schedule at fixed steps. Records the crossings in
  /// it in time order up to a terminal one; true when a terminal one stopped it (then stop_state(),
  /// stopping_event()). A crossing is where g reaches zero or passes it: a step that starts at zero
  /// has none (the run's start, or the end of the step that reached it, which counted it once). An own step beyond the run's
  /// end is read up to the end. After a stop it goes on locating, and holds the crossings it finds
  /// (those of the stopping step after the terminal one too) until resume(); it returns true until then.
  bool step_to(const CartState& after);
  /// The run goes on after a terminal stop (the node's ~pause false): the held crossings are
  /// recorded, up to the next terminal one (then true again, as step_to()).
  bool resume();

  bool stopped() const { return stopped_; }
  /// The state at the terminal crossing [SI].
  const CartState& stop_state() const { return stop_state_; }
  /// The index in `events` of the one that stopped the run.
  std::size_t stopping_event() const { return stopping_event_; }
  /// The work of locating (dense output, the steps beside the run): never in the run's statistics.
  const StepStatistics& work() const { return *work_; }

 private:
  /// The state at `time` in the step from before_; false when the member has none there (a step
  /// of a control whose dense output restarts at an actuator's kink).
  bool state_in_step(double time, CartState& out);
  struct Found {
    double time;  ///< [s]
    std::size_t event;
    CartState state;
  };
  /// Appends `found` (in time order) to the events up to a terminal one, the rest to pending_.
  void record(const std::vector<Found>& found);
  double value(const StateEvent& event, const CartState& state) const;

  const Simulation& simulation_;
  std::vector<StateEvent>& events_;
  double time_tolerance_;  ///< [s]
  bool own_steps_;
  CartState before_;
  std::vector<double> g_before_;
  std::vector<double> g_after_;  ///< step_to's buffer for g at the step's end
  bool stopped_ = false;
  CartState stop_state_;
  std::size_t stopping_event_ = 0;
  std::vector<Found> pending_;  ///< crossings after the terminal one, until resume()
  StepStatistics own_work_;
  StepStatistics* work_;
};

/// One recorded crossing: its time [s], the index of its event and its index among that event's.
struct Occurrence {
  double time;
  std::size_t event;
  std::size_t index;
};
/// Every recorded crossing of `events`, in time order (ties in the events' order).
std::vector<Occurrence> occurrences_in_time_order(const std::vector<StateEvent>& events);

/// "chi=0.3,rising at t = 1.2345678901234567 s: x = … m, y = … m, theta = … rad, chi = … rad,
/// omega1 = … m/s, omega2 = … rad/s" (17 significant digits), one line without newline.
std::string describe_occurrence(const StateEvent& event, std::size_t occurrence);

}  // namespace birkhoff_cart
