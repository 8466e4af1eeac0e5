// birkhoff_cart.simulator: the simulator as a Python module (pybind11, numpy). It translates only:
// scenes come through the core's scene reader (scene_source.h), runs through GuardedRun
// (core/guarded_run.h: the run loop with its accuracy guard that cart_simulate and cart_sim share), and the arrays it returns are
// the core's CartState, Diagnostics and guard values in SI units. The long loops (a batch of steps,
// a run, a time grid) run in C++ with the GIL released, so a Python loop that advances many steps per
// call pays the crossing once; calls on one Simulation from several threads take its lock one at a
// time, waiting for it without the GIL. solve() runs a scene whole and returns it shaped like
// scipy's solve_ivp result: its own steps, t_eval's states and the events' crossings read on the way
// from the member's dense output (Simulation::newest_step_state; at fixed steps one step of the
// member beside the run, Simulation::state_by_one_step), located by the core's EventLocator (state_events.h); only the event
// functions are called with the GIL held. docs/python.md.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "birkhoff_cart/core/scene/accuracy_guard.h"
#include "birkhoff_cart/core/cart_binding/cart_stepper.h"
#include "birkhoff_cart/core/cart_binding/integrator_registry.h"
#include "birkhoff_cart/core/run/run_summary.h"
#include "birkhoff_cart/core/scene/scene.h"
#include "birkhoff_cart/core/support/version.h"
#include "birkhoff_cart/core/run/guarded_run.h"
#include "birkhoff_cart/core/run/state_events.h"
#include "birkhoff_cart/core/integrators/richardson_shadow.h"
#include "event_specs.h"
#include "own_system_bindings.h"
#include "scene_source.h"

namespace py = pybind11;

namespace birkhoff_cart {
namespace python {
namespace {

/// The columns of a state row, in order, each in SI units (docs/python.md): scene time, the hinge
/// B, heading, steering angle, wheel angles, arc length, quasi-velocities, work and impulse.
constexpr std::size_t kStateFieldsCount = 14;
const std::vector<std::string> kStateFields = {"t",    "x",    "y",    "theta", "chi",    "phi1",       "phi2",
                                               "phi3", "phi4", "pi1",  "omega1", "omega2", "applied_work",
                                               "steering_impulse"};
/// The columns of a diagnostics row (docs/python.md).
const std::vector<std::string> kDiagnosticFields = {
    "energy",          "p2",
    "energy_balance_residual", "p2_balance_residual",
    "max_constraint_residual", "reference_position_error",
    "reference_heading_error", "reference_arc_length_relative_error",
    "local_error_estimate"};

using Row = std::vector<double>;

/// The states a call may return at most (step(record=True), run_to): 2**20 rows of STATE_FIELDS,
/// 117 MB as float64 (plus the C++ states they come from during the call). A longer call is refused
/// before any step.
constexpr std::uint64_t kMaxRecordedStates = 1u << 20;

/// The Python face of a GuardedRun: the run and the lock that makes calls from several threads take
/// their turns.
struct SharedRun : GuardedRun {
  using GuardedRun::GuardedRun;
  std::mutex busy;
};

/// The run's lock, waited for with the GIL released (the thread that holds the lock may need the GIL
/// to finish its call), taken at once when free.
std::unique_lock<std::mutex> hold(SharedRun& run) {
  std::unique_lock<std::mutex> lock(run.busy, std::try_to_lock);
  if (!lock.owns_lock()) {
    py::gil_scoped_release release;
    lock.lock();
  }
  return lock;
}

/// A property getter reading the run's simulation under its lock.
template <typename Get>
auto read_locked(Get get) {
  return [get](SharedRun& run) {
    const auto lock = hold(run);
    return get(run.simulation());
  };
}

/// Refuses a call that would return more than kMaxRecordedStates states, naming it and the bound.
void require_recordable(std::uint64_t states, const std::string& call) {
  if (states <= kMaxRecordedStates) return;
  const std::uint64_t row = kStateFieldsCount * sizeof(double);  // [bytes]
  throw py::value_error(call + " would return " + std::to_string(states) + " states (" +
                        std::to_string(states * row / 1000000) + " MB as float64), beyond the bound of " +
                        std::to_string(kMaxRecordedStates) + " states a call (MAX_RECORDED_STATES, " +
                        std::to_string(kMaxRecordedStates * row / 1000000) +
                        " MB): nothing was taken; cut it into calls, or step without record");
}

Row state_row(const CartState& s) {
  return {s.time,
          s.x,
          s.y,
          s.heading,
          s.steering_angle,
          s.wheel_spin_angle[0],
          s.wheel_spin_angle[1],
          s.wheel_spin_angle[2],
          s.wheel_spin_angle[3],
          s.arc_length,
          s.forward_speed,
          s.steering_rate,
          s.applied_work,
          s.steering_impulse};
}

Row diagnostics_row(const Simulation& simulation) {
  const Diagnostics d = simulation.diagnostics();
  const StepStatistics& statistics = simulation.statistics();
  const double estimate = has_local_error_estimate(statistics) ? statistics.local_error_estimate_last_step
                                                               : std::numeric_limits<double>::quiet_NaN();
  return {d.energy,
          simulation.model().steering_momentum(simulation.state()),
          d.energy_balance_residual,
          d.p2_balance_residual,
          d.max_constraint_residual,
          d.reference_position_error,
          d.reference_heading_error,
          d.reference_arc_length_relative_error,
          estimate};
}

py::array_t<double> vector_array(const Row& row) {
  py::array_t<double> array(static_cast<py::ssize_t>(row.size()));
  std::copy(row.begin(), row.end(), array.mutable_data());
  return array;
}

/// The states as rows of STATE_FIELDS (states × STATE_FIELDS, C order).
py::array_t<double> states_array(const std::vector<CartState>& states) {
  py::array_t<double> array({static_cast<py::ssize_t>(states.size()), static_cast<py::ssize_t>(kStateFieldsCount)});
  double* out = array.mutable_data();
  for (const CartState& state : states) {
    const Row row = state_row(state);
    out = std::copy(row.begin(), row.end(), out);
  }
  return array;
}

/// rows × columns, C order.
py::array_t<double> matrix_array(const std::vector<Row>& rows, std::size_t columns) {
  py::array_t<double> array({static_cast<py::ssize_t>(rows.size()), static_cast<py::ssize_t>(columns)});
  double* out = array.mutable_data();
  for (const Row& row : rows) out = std::copy(row.begin(), row.end(), out);
  return array;
}

py::tuple names_tuple(const std::vector<std::string>& names) {
  py::tuple tuple(names.size());
  for (std::size_t i = 0; i < names.size(); ++i) tuple[i] = py::str(names[i]);
  return tuple;
}

/// One torque argument of step(): None (keep the command), a number (command it now, held), or one
/// value per step. A number is returned (NaN otherwise); per-step values go into commands (count
/// entries) through `field`.
double read_torque(const py::object& torque, const char* name, std::size_t count, std::vector<StepCommands>& commands,
                   double StepCommands::*field) {
  constexpr double kNone = std::numeric_limits<double>::quiet_NaN();
  if (torque.is_none()) return kNone;
  const py::array given = py::array::ensure(torque);
  const char kind = given ? given.dtype().kind() : '?';
  if (kind != 'i' && kind != 'u' && kind != 'f') {  // no str, bool or object: a torque is a number
    throw py::type_error(std::string(name) + " must be None, a number [N·m] or numbers, one per step; got " +
                         std::string(py::repr(torque)) + " (" +
                         std::string(py::str(torque.get_type().attr("__name__"))) + ")");
  }
  const auto values = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(torque);
  if (values && values.ndim() == 0) {
    const double value = values.data()[0];
    if (std::isnan(value)) throw py::value_error(std::string(name) + " is NaN: a torque command must be finite");
    return value;
  }
  if (!values || values.ndim() != 1 || static_cast<std::size_t>(values.shape(0)) != count) {
    throw py::value_error(std::string(name) + " must be None, a number [N·m] or one value per step (" +
                          std::to_string(count) + " values)");
  }
  if (commands.empty()) commands.resize(count);
  for (std::size_t k = 0; k < count; ++k) {
    const double value = values.data()[k];
    if (std::isnan(value)) {
      throw py::value_error(std::string(name) + "[" + std::to_string(k) + "] is NaN: a torque command must be finite");
    }
    commands[k].*field = value;
  }
  return kNone;
}

py::dict accuracy_dict(const AccuracyGuard& guard) {
  std::vector<double> largest, current;
  std::vector<std::string> quantities;
  for (AccuracyQuantity quantity : kLimitedAccuracyQuantities) {
    quantities.emplace_back(to_string(quantity));
    largest.push_back(guard.largest_value(quantity));
    current.push_back(guard.current_value(quantity));
  }
  py::dict verdict;
  verdict["level"] = to_string(guard.level());
  verdict["summary"] = guard.summary();
  verdict["quantities"] = names_tuple(quantities);
  verdict["largest"] = vector_array(largest);
  verdict["current"] = vector_array(current);
  return verdict;
}

py::dict statistics_dict(const StepStatistics& statistics) {
  py::dict counts;
  counts["steps"] = statistics.steps;
  counts["rhs_evaluations"] = statistics.rhs_evaluations;
  counts["passive_evaluations"] = statistics.passive_evaluations;
  counts["newton_iterations"] = statistics.newton_iterations_total;
  counts["internal_steps"] = statistics.internal_steps;
  // Attempts a step control rejected (the reversible control: its restarts with a smaller ε; at fixed
  // steps, the steps taken in substeps): the rejected share is rejected_steps / internal_steps.
  counts["rejected_steps"] = statistics.rejected_steps;
  counts["local_error_estimate_max"] = statistics.local_error_estimate_max;
  counts["local_error_estimate_sum"] = statistics.local_error_estimate_sum;
  // The adaptive control's global error estimate (docs/accuracy.md §4.5): NaN when not asked for.
  counts["global_error_estimate"] = statistics.global_error_estimate;
  counts["global_error_estimate_in_range"] =
      global_error_estimate_in_range(statistics.global_error_paired_steps, statistics.global_error_stiffness);
  return counts;
}

py::list integrator_list() {
  py::list members;
  for (const IntegratorEntry& member : integrator_registry()) {
    py::dict row;
    row["name"] = member.name;
    row["order"] = member.order;
    row["symmetric"] = member.symmetric;
    row["kind"] = to_string(member.kind);
    row["reversible"] = member.reversible();
    row["adaptive"] = member.adaptive();
    row["takes_tolerance"] = member.takes_tolerance();
    row["vector_stages"] = member.vector_stages;
    row["description"] = member.description;
    members.append(row);
  }
  return members;
}

/// Python exception types of the module (created once at import; kept for the process's life).
PyObject* scene_error_type = nullptr;
PyObject* step_error_type = nullptr;
PyObject* end_of_run_error_type = nullptr;

/// C++ text as a str: UTF-8, any byte that is not shown as \xNN (a path's own bytes).
py::str text(const std::string& bytes) {
  return py::reinterpret_steal<py::str>(
      PyUnicode_DecodeUTF8(bytes.data(), static_cast<Py_ssize_t>(bytes.size()), "backslashreplace"));
}

/// Raises `type` with the message `message` and the attributes `attributes` set on it.
void raise_with(PyObject* type, const std::string& message, const py::dict& attributes) {
  py::object instance = py::reinterpret_borrow<py::object>(type)(text(message));
  for (const auto& [name, value] : attributes) py::setattr(instance, name, value);
  PyErr_SetObject(type, instance.ptr());
}

void translate_exceptions(std::exception_ptr pending) {
  try {
    if (pending) std::rethrow_exception(pending);
  } catch (const SceneError& error) {
    py::dict attributes;
    attributes["key"] = text(error.key());
    attributes["file"] = text(error.file());
    raise_with(scene_error_type, error.what(), attributes);
  } catch (const StepError& error) {
    PyErr_SetObject(step_error_type, text(error.what()).ptr());
  }
}

/// A StepError raised from a call that recorded states: error.states holds those of the steps taken
/// before the failing one (the simulation keeps the last of them).
[[noreturn]] void raise_step_error(const StepError& error, const std::vector<CartState>& states) {
  py::dict attributes;
  attributes["states"] = states_array(states);
  raise_with(step_error_type, error.what(), attributes);
  throw py::error_already_set();
}

// ---------------------------------------------------------------------------------------------
// solve(): a whole run shaped like scipy's solve_ivp result (docs/python.md "solve").

/// What solve() returns; its fields are set as attributes (py::dynamic_attr).
struct SolveResult {};

/// sol of a solve(): the run's states at any instants of [t0, t_final], by running the scene again
/// to them (the member's own steps do not depend on the instants asked for, so the states are the
/// run's own).
struct DenseSolution {
  Scene scene;
  double t_min = 0.0;  ///< [s]
  double t_max = 0.0;  ///< [s]
};

/// Thrown from the grid observer to stop a run at a terminal event.
struct TerminalStop {};

/// solve()'s default for the width of the bracket a crossing is located in [s] (locate_crossing).
constexpr double kDefaultEventTolerance = EventLocator::kDefaultTimeTolerance;

/// solve()'s events as the core's (state_events.h): g(t, state) called on a STATE_FIELDS row, with
/// the GIL held (drive() keeps it while there are events).
std::vector<StateEvent> read_events(const py::object& events) {
  std::vector<StateEvent> functions;
  std::size_t index = 0;
  for (const python::EventSpec& spec : python::read_event_specs(events)) {
    StateEvent event;
    event.name = "events[" + std::to_string(index++) + "]";
    event.g = [g = spec.g](const CartState& state) {
      return py::float_(g(state.time, vector_array(state_row(state)))).cast<double>();
    };
    event.direction = spec.direction;
    event.terminal_after = spec.terminal_after;
    functions.push_back(std::move(event));
  }
  return functions;
}

/// A whole run of solve() (and of sol's runs again): the own steps, the states at t_eval, how it ended.
struct DrivenRun {
  std::vector<CartState> steps;    ///< the member's own steps from t0 (the schedule's at fixed steps)
  std::vector<CartState> outputs;  ///< at t_eval
  int status = 0;                  ///< 0: the end; 1: a terminal event; −1: a failed step
  std::string message = "The solver successfully reached the end of the integration interval.";
  std::size_t stopping_event = 0;
  StepStatistics statistics;
  StepStatistics reading;  ///< the work of reading t_eval and the crossings beside the run (dense output, one steps)
  std::string integrator;
};

/// Refuses t_eval unless it increases within [t0, end] [s], naming the entry.
void require_t_eval(const std::vector<double>& t_eval, double t0, double end) {
  for (std::size_t j = 0; j < t_eval.size(); ++j) {
    const double t = t_eval[j];
    if (!(t >= t0 && t <= end) || (j > 0 && !(t > t_eval[j - 1]))) {
      std::ostringstream text;
      text.precision(17);
      text << "t_eval[" << j << "] = " << t << " s: the times must increase within the run [" << t0 << ", " << end
           << "] s";
      throw py::value_error(text.str());
    }
  }
}

/// The scene's run from its start to its end or a terminal event. A member with its own steps is
/// called for the scene's first step t0 + h (as cart_simulate's first step: dopri5 takes it as its
/// first trial step) and then for the end; everything else is read on the way, at each own step,
/// from the dense output of that step (Simulation::newest_step_state): t_eval's states and the
/// events' crossings, located by locate_crossing to `event_tolerance` [s]. So the own steps do not
/// depend on t_eval or the events, and a run again with other t_eval (sol) is the same run. A t_eval
/// instant in a step without dense output (one that ends at an actuator's kink, where the grid
/// restarts) is taken after the run by a run of its own to it (its dense output there). A member at
/// fixed steps records the schedule's steps; its crossings are located on states reached by one
/// step of the member from the step's start (Simulation::state_by_one_step); t_eval takes the
/// schedule's instants, by a run of its own (GuardedRun::states_at). Event functions are called
/// with the GIL held.
DrivenRun drive(const Scene& scene, const std::vector<double>& t_eval, std::vector<StateEvent>& events,
                double event_tolerance) {
  DrivenRun run;
  Simulation simulation(scene);
  run.integrator = simulation.integrator_name();
  const bool own_steps = simulation.takes_own_steps();
  const double t0 = simulation.state().time;  // [s]
  const double end = simulation.end_time();    // [s]
  require_t_eval(t_eval, t0, end);
  std::vector<std::uint64_t> t_eval_steps;  // at fixed steps: the step count of each t_eval instant
  if (!own_steps) {
    require_recordable(simulation.schedule().total_steps() + 1, "solve()'s steps");
    for (double t : t_eval) {
      t_eval_steps.push_back(schedule_step_at(simulation.schedule(), t, simulation.integrator_name()));
    }
  }
  std::optional<EventLocator> locator;  // refuses, by the core's reason, events it cannot locate
  try {
    if (!events.empty()) locator.emplace(simulation, events, event_tolerance, &run.reading);
  } catch (const std::invalid_argument& error) {
    throw py::value_error(error.what());
  }

  std::vector<CartState>& steps = run.steps;
  std::vector<CartState>& outputs = run.outputs;
  steps.push_back(simulation.state());
  std::size_t next_output = 0;  // the next t_eval entry to output
  std::vector<double> deferred;  // t_eval entries without dense output where they fell
  std::vector<std::size_t> deferred_at;  // their places in outputs
  for (; own_steps && next_output < t_eval.size() && t_eval[next_output] == t0; ++next_output) {
    outputs.push_back(steps.front());
  }
  CartState stop_state;
  double stop_time = std::numeric_limits<double>::infinity();  // [s]
  // The crossings of the step to `after` up to a terminal one (then true, with stop_time and stop_state set).
  const auto crossings_in_step = [&](const CartState& after) {
    if (!locator->step_to(after)) return false;
    stop_state = locator->stop_state();
    stop_time = events[locator->stopping_event()].times.back();
    run.stopping_event = locator->stopping_event();
    return true;
  };

  // Each own step: its crossings, then t_eval's instants in it up to a terminal crossing.
  const auto on_step = [&](const CartState& stepped_to) {
    if (steps.size() >= kMaxRecordedStates) require_recordable(steps.size() + 1, "solve()'s own steps");
    // A step past the run's end (dopri5's and the reversible control's last, which the run leaves
    // by a side step to the end) is read up to the end only, and not kept as an own step.
    const bool beyond_end = stepped_to.time > end;
    CartState clipped;
    if (beyond_end && !simulation.newest_step_state(end, clipped, &run.reading)) return;
    const CartState& grid_state = beyond_end ? clipped : stepped_to;
    const bool stop = !events.empty() && crossings_in_step(grid_state);
    const double reach = std::min(grid_state.time, stop_time);  // [s]
    for (; next_output < t_eval.size() && t_eval[next_output] <= reach && t_eval[next_output] < end; ++next_output) {
      const double t = t_eval[next_output];
      CartState at = grid_state;
      if (stop && t == stop_time) {
        at = stop_state;
      } else if (t != grid_state.time && !simulation.newest_step_state(t, at, &run.reading)) {
        deferred.push_back(t);
        deferred_at.push_back(outputs.size());
      }
      outputs.push_back(at);
    }
    if (stop) {
      steps.push_back(stop_state);
      throw TerminalStop{};
    }
    if (!beyond_end) steps.push_back(grid_state);
  };

  std::optional<py::gil_scoped_release> released;  // the GIL stays only for the event functions
  if (events.empty()) released.emplace();
  try {
    if (own_steps) {
      simulation.observe_grid(on_step);
      try {
        const double first = std::min(t0 + simulation.step_size(), end);  // [s]
        simulation.advance_output_to(first);
        if (first < end) simulation.advance_output_to(end);
        // The run's end as an own step where the grid did not land on it (dopri5, the reversible
        // control: their side step to the end).
        if (steps.back().time != end) steps.push_back(simulation.state());
        for (; next_output < t_eval.size(); ++next_output) outputs.push_back(steps.back());  // t_eval's end
      } catch (const TerminalStop&) {
        run.status = 1;
        run.message = "A termination event occurred.";
        for (; next_output < t_eval.size() && t_eval[next_output] <= stop_state.time; ++next_output) {
          outputs.push_back(stop_state);  // at the end itself, which the steps leave to the run's end
        }
      }
      simulation.observe_grid({});
      if (!deferred.empty()) {
        GuardedRun again(scene);
        const std::vector<CartState> states = again.states_at(deferred);
        for (std::size_t k = 0; k < states.size(); ++k) outputs[deferred_at[k]] = states[k];
        run.reading.rhs_evaluations += again.simulation().statistics().rhs_evaluations;
      }
    } else {
      try {
        while (!simulation.at_end()) {
          simulation.step_on_schedule();
          if (!events.empty() && crossings_in_step(simulation.state())) {
            run.status = 1;
            run.message = "A termination event occurred.";
            steps.push_back(stop_state);
            break;
          }
          steps.push_back(simulation.state());
        }
      } catch (const StepError& error) {
        run.status = -1;
        run.message = error.what();
      }
      // t_eval: the schedule's steps the run reached (before a crossing that stopped it), and the
      // crossing's own instant.
      const std::size_t scheduled = run.status == 1 ? steps.size() - 1 : steps.size();  // steps[n]: after n steps
      for (std::size_t j = 0; j < t_eval.size(); ++j) {
        if (t_eval_steps[j] < scheduled && !(t_eval[j] > stop_time)) {
          outputs.push_back(steps[t_eval_steps[j]]);
        } else {
          if (run.status == 1 && t_eval[j] == stop_time) outputs.push_back(stop_state);
          break;
        }
      }
    }
  } catch (const StepError& error) {
    simulation.observe_grid({});
    run.status = -1;
    run.message = error.what();
  } catch (...) {
    simulation.observe_grid({});
    throw;
  }
  released.reset();
  run.statistics = simulation.statistics();
  return run;
}

std::vector<double> times_of(const py::object& given, const char* name) {
  const auto times = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(given);
  if (!times) throw py::type_error(std::string(name) + " must be numbers [s]");
  return std::vector<double>(times.data(), times.data() + times.size());
}

py::object solve(const Scene& scene, const py::object& t_eval_given, bool dense_output, const py::object& events_given,
                 double event_tolerance) {
  if (!(event_tolerance > 0.0)) throw py::value_error("event_tolerance must be > 0 [s]");
  std::vector<StateEvent> events = read_events(events_given);
  const bool with_t_eval = !t_eval_given.is_none();
  std::vector<double> t_eval;
  if (with_t_eval) {
    t_eval = times_of(t_eval_given, "t_eval");
    require_recordable(t_eval.size(), "solve(t_eval of " + std::to_string(t_eval.size()) + " times)");
  }
  const DrivenRun run = drive(scene, t_eval, events, event_tolerance);
  const std::vector<CartState>& shown = with_t_eval ? run.outputs : run.steps;
  py::object result = py::cast(SolveResult{});
  const py::object y = states_array(shown).attr("T").attr("copy")();  // STATE_FIELDS × times
  result.attr("t") = y[py::int_(0)].attr("copy")();
  result.attr("y") = y;
  const py::object y_steps = states_array(run.steps).attr("T").attr("copy")();
  result.attr("t_steps") = y_steps[py::int_(0)].attr("copy")();
  result.attr("y_steps") = y_steps;
  result.attr("sol") = dense_output ? py::cast(DenseSolution{scene, run.steps.front().time, run.steps.back().time})
                                    : py::object(py::none());
  py::list t_events, y_events;
  for (const StateEvent& function : events) {
    t_events.append(vector_array(function.times));
    y_events.append(states_array(function.states));  // occurrences × STATE_FIELDS, as solve_ivp's
  }
  result.attr("t_events") = events.empty() ? py::object(py::none()) : py::object(t_events);
  result.attr("y_events") = events.empty() ? py::object(py::none()) : py::object(y_events);
  result.attr("nfev") = run.statistics.rhs_evaluations + run.reading.rhs_evaluations;
  result.attr("njev") = py::none();  // no count kept: statistics["newton_iterations"] is the implicit members' work
  result.attr("nlu") = py::none();
  result.attr("nsteps") = run.steps.size() - 1;
  result.attr("status") = run.status;
  result.attr("message") = text(run.message);
  result.attr("success") = run.status >= 0;
  result.attr("integrator") = run.integrator;
  result.attr("statistics") = statistics_dict(run.statistics);
  result.attr("terminal_event") = run.status == 1 ? py::object(py::int_(run.stopping_event)) : py::object(py::none());
  return result;
}

/// sol(t): the states at `t` (a number: STATE_FIELDS; numbers: STATE_FIELDS × len(t)), any order,
/// by the same run again with t as its t_eval.
py::object dense_states(const DenseSolution& dense, const py::object& t) {
  const bool scalar = py::array::ensure(t) && py::array::ensure(t).ndim() == 0;
  const std::vector<double> asked = times_of(t, "sol(t): t");
  require_recordable(asked.size(), "sol(" + std::to_string(asked.size()) + " times)");
  for (double time : asked) {
    if (!(time >= dense.t_min && time <= dense.t_max)) {
      std::ostringstream text;
      text.precision(17);
      text << "sol(t): t = " << time << " s is outside the run's [" << dense.t_min << ", " << dense.t_max << "] s";
      throw py::value_error(text.str());
    }
  }
  std::vector<double> sorted = asked;
  std::sort(sorted.begin(), sorted.end());
  sorted.erase(std::unique(sorted.begin(), sorted.end()), sorted.end());
  std::vector<StateEvent> none;
  const DrivenRun run = drive(dense.scene, sorted, none, kDefaultEventTolerance);
  if (run.outputs.size() < sorted.size()) {  // the run failed before the last instant asked
    throw py::value_error("sol(t): the run again ended before t = " + std::to_string(sorted[run.outputs.size()]) +
                          " s: " + run.message);
  }
  std::vector<CartState> ordered;
  ordered.reserve(asked.size());
  for (double time : asked) {
    ordered.push_back(run.outputs[std::lower_bound(sorted.begin(), sorted.end(), time) - sorted.begin()]);
  }
  if (scalar) return vector_array(state_row(ordered.front()));
  return states_array(ordered).attr("T").attr("copy")();
}

}  // namespace
}  // namespace python
}  // namespace birkhoff_cart

PYBIND11_MODULE(simulator, m) {
  using namespace birkhoff_cart;
  using namespace birkhoff_cart::python;
  m.doc() =
      "The birkhoff_cart simulator: load a scene (file or dict), build a simulation with any member of the "
      "integrator registry and step control, step it with torque commands, run it to a time grid, read its state, "
      "diagnostics and accuracy verdict as numpy arrays. docs/python.md.";
  m.attr("__version__") = package_version();

  scene_error_type = PyErr_NewExceptionWithDoc(
      "birkhoff_cart.simulator.SceneError",
      "A scene that cannot be used (a ValueError): .key names the scene key, .file the file (or '<dict>').",
      PyExc_ValueError, nullptr);
  step_error_type = PyErr_NewExceptionWithDoc(
      "birkhoff_cart.simulator.StepError",
      "A step that failed (a RuntimeError); the simulation keeps the state of the last good step.",
      PyExc_RuntimeError, nullptr);
  end_of_run_error_type = PyErr_NewExceptionWithDoc(
      "birkhoff_cart.simulator.EndOfRunError",
      "step() asked for steps of a run that is at its end (a RuntimeError, as scipy's solvers raise); nothing "
      "moved: reset() starts it again.",
      PyExc_RuntimeError, nullptr);
  m.attr("SceneError") = py::handle(scene_error_type);
  m.attr("StepError") = py::handle(step_error_type);
  m.attr("EndOfRunError") = py::handle(end_of_run_error_type);
  py::register_exception_translator(&translate_exceptions);
  m.attr("MAX_RECORDED_STATES") = kMaxRecordedStates;
  m.attr("MAX_SCENE_BYTES") = kMaxSceneBytes;
  m.attr("MAX_SCENE_DEPTH") = kMaxSceneDepth;
  // numpy's C API table is a function-local static that imports numpy when first used: look it up
  // now, under the import lock, so that no thread later holds its guard while another holds the GIL.
  py::detail::npy_api::get();

  m.attr("STATE_FIELDS") = names_tuple(kStateFields);
  m.attr("DIAGNOSTIC_FIELDS") = names_tuple(kDiagnosticFields);

  m.def("integrators", &integrator_list,
        "The integrator registry: one dict per member (name, order, symmetric, kind, reversible, adaptive, "
        "takes_tolerance, vector_stages, description), in its order.");
  m.def("load_scene", &scene_from, py::arg("source"), py::arg("overrides") = py::none(),
        "A validated Scene from a scene file's path or a dict shaped like one, with `overrides` (a dict) merged "
        "into it first: maps key by key, None removes a key. Raises SceneError naming the key.");
  m.def("scene_document", &scene_document, py::arg("path"),
        "The scene file at `path` as a dict, to edit and pass to load_scene.");

  py::class_<Scene>(m, "Scene", "A validated scene (plain data): see load_scene.")
      .def_property_readonly("name", [](const Scene& s) { return s.name; })
      .def_property_readonly("source", [](const Scene& s) { return s.source_path; })
      .def_property_readonly("description", [](const Scene& s) { return s.description; })
      .def_property_readonly("start_time", [](const Scene& s) { return s.initial_state.time; }, "t0 [s]")
      .def_property_readonly("duration", [](const Scene& s) { return s.duration; }, "[s]")
      .def_property_readonly("integrator", [](const Scene& s) { return s.integrator.name; })
      .def_property_readonly("step_size", [](const Scene& s) { return s.integrator.step_size; }, "h [s]")
      .def_property_readonly("step_control", [](const Scene& s) { return std::string(to_string(s.integrator.step_control)); })
      .def_property_readonly("birkhoffian_form",
                             [](const Scene& s) { return std::string(to_string(s.integrator.birkhoffian_form)); })
      .def_property_readonly("output_rate", [](const Scene& s) { return s.output_rate; }, "[Hz]")
      .def_property_readonly("effects",
                             [](const Scene& s) {
                               std::vector<std::string> names;
                               for (const EffectSpec& spec : s.effects) names.push_back(spec.name);
                               return names;
                             })
      .def("__repr__", [](const Scene& s) {
        std::ostringstream text;
        text << "<Scene '" << s.name << "': " << s.integrator.name << " (" << to_string(s.integrator.step_control)
             << "), h = " << s.integrator.step_size << " s, " << s.duration << " s>";
        return text.str();
      });

  py::class_<SolveResult>(m, "SolveResult", py::dynamic_attr(),
                          "What solve() returns, shaped like scipy's solve_ivp result (docs/python.md \"solve\").")
      .def("__repr__", [](py::object self) {
        std::ostringstream text;
        text << "<SolveResult " << std::string(py::str(self.attr("integrator"))) << ": status "
             << std::string(py::str(self.attr("status"))) << ", " << std::string(py::str(self.attr("nsteps")))
             << " steps, " << std::string(py::str(self.attr("message"))) << ">";
        return text.str();
      });
  py::class_<DenseSolution>(m, "DenseSolution",
                            "sol of solve(dense_output=True): sol(t) is the run's state at t [s] (STATE_FIELDS; "
                            "for an array of times STATE_FIELDS x len(t)), by running the scene again to them.")
      .def("__call__", &dense_states, py::arg("t"))
      .def_readonly("t_min", &DenseSolution::t_min, "[s]")
      .def_readonly("t_max", &DenseSolution::t_max, "[s]");
  m.def("solve", &solve, py::arg("scene"), py::arg("t_eval") = py::none(), py::arg("dense_output") = false,
        py::arg("events") = py::none(), py::arg("event_tolerance") = kDefaultEventTolerance,
        "The scene's whole run from its start, returned like scipy's solve_ivp: t, y (STATE_FIELDS x times), "
        "t_steps and y_steps (the member's own steps), sol (dense_output=True), t_events and y_events (events: "
        "callables g(t, state) with .terminal and .direction, located on the dense output, or at fixed steps on "
        "one step of the member, to event_tolerance [s]), nfev, njev, nlu, nsteps, status, message, success, statistics. docs/python.md.");

  py::class_<SharedRun>(m, "Simulation",
                        "A running scene with its accuracy guard, checked where cart_simulate checks it: at the "
                        "start, at every output instant t0 + k/output_rate on the step grid, and at the end. Calls "
                        "from several threads take their turns.")
      .def(py::init<const Scene&>(), py::arg("scene"), py::call_guard<py::gil_scoped_release>())
      .def("state", [](SharedRun& run) {
             const auto lock = hold(run);
             return vector_array(state_row(run.simulation().state()));
           },
           "The state now, as STATE_FIELDS (SI units).")
      .def("diagnostics", [](SharedRun& run) {
             const auto lock = hold(run);
             return vector_array(diagnostics_row(run.simulation()));
           },
           "Invariants and errors now, as DIAGNOSTIC_FIELDS (SI units; NaN where there is none).")
      .def("statistics", [](SharedRun& run) {
        const auto lock = hold(run);
        return statistics_dict(run.simulation().statistics());
      })
      .def("accuracy", [](SharedRun& run) {
             const auto lock = hold(run);
             return accuracy_dict(run.guard());
           },
           "The accuracy guard's verdict: level (OK, WARN, ERROR), summary, and the largest and current value of "
           "each guarded quantity.")
      .def("summary", [](SharedRun& run) {
             const auto lock = hold(run);
             return run_summary(run.simulation(), run.guard());
           },
           "cart_simulate's summary of the run.")
      .def(
          "step",
          [](SharedRun& run, py::ssize_t count, const py::object& steering_torque, const py::object& drive_torque,
             bool record) -> py::object {
            if (count < 0) throw py::value_error("count must be >= 0, got " + std::to_string(count));
            const std::size_t n = static_cast<std::size_t>(count);
            std::vector<StepCommands> commands;
            const double steering = read_torque(steering_torque, "steering_torque", n, commands, &StepCommands::steering);
            const double drive = read_torque(drive_torque, "drive_torque", n, commands, &StepCommands::drive);
            const auto lock = hold(run);
            Simulation& simulation = run.simulation();
            if (n > 0 && simulation.at_end()) {
              std::ostringstream message;
              message << "step(" << n << "): the run is at its end, t = " << simulation.end_time()
                      << " s, after " << simulation.steps_taken() << " steps; nothing moved (reset() starts it again)";
              raise_with(end_of_run_error_type, message.str(), py::dict());
              throw py::error_already_set();
            }
            if (record) {
              const StepSchedule& schedule = simulation.schedule();
              const std::uint64_t left = schedule.total_steps() - std::min(schedule.total_steps(), simulation.steps_taken());
              require_recordable(std::min<std::uint64_t>(n, left), "step(" + std::to_string(n) + ", record=True)");
            }
            if (!std::isnan(steering)) simulation.set_steering_command(steering);
            if (!std::isnan(drive)) simulation.set_drive_command(drive);
            std::vector<CartState> states;
            try {
              py::gil_scoped_release release;
              run.advance(n, commands, record, &states);
            } catch (const StepError& error) {
              if (!record) throw;
              raise_step_error(error, states);
            }
            if (!record) return vector_array(state_row(simulation.state()));
            return states_array(states);
          },
          py::arg("count") = 1, py::arg("steering_torque") = py::none(), py::arg("drive_torque") = py::none(),
          py::arg("record") = false,
          "Up to `count` steps of the run's schedule (fewer at its end; EndOfRunError at it). A torque [N·m] given "
          "as a number is commanded now and held (zero-order hold; count=0 only commands), as an array one value "
          "per step. Returns the state after the last step, or with record=True the state after each (count × "
          "STATE_FIELDS, at most MAX_RECORDED_STATES rows; a StepError then holds the states before it as .states).")
      .def(
          "run",
          [](SharedRun& run) {
            const auto lock = hold(run);
            {
              py::gil_scoped_release release;
              run.run_to_end();
            }
            return vector_array(state_row(run.simulation().state()));
          },
          "Steps to the run's end; returns the final state.")
      .def(
          "run_to",
          [](SharedRun& run, const std::vector<double>& times, bool diagnostics) -> py::object {
            require_recordable(times.size(), "run_to(" + std::to_string(times.size()) + " times)");
            const auto lock = hold(run);
            std::vector<CartState> states;  // each one as run_to reaches it: kept when a later step fails
            std::vector<Row> diagnostic_rows;
            try {
              py::gil_scoped_release release;
              run.states_at(times, [&](const Simulation& simulation) {
                states.push_back(simulation.state());
                if (diagnostics) diagnostic_rows.push_back(diagnostics_row(simulation));
              });
            } catch (const StepError& error) {
              raise_step_error(error, states);
            }
            py::array_t<double> state_array = states_array(states);
            if (!diagnostics) return std::move(state_array);
            return py::make_tuple(state_array, matrix_array(diagnostic_rows, kDiagnosticFields.size()));
          },
          py::arg("times"), py::arg("diagnostics") = false,
          "The states at `times` [s] (increasing, from now to the end; at most MAX_RECORDED_STATES), advancing the "
          "run to the last; with diagnostics=True also the diagnostics there: (states, diagnostics). A member with "
          "its own steps (a step control, dopri5) gives any instant from its dense output; a member at fixed steps "
          "the step schedule's. A StepError holds the states reached before it as .states.")
      .def(
          "reset",
          [](SharedRun& run) {
            const auto lock = hold(run);
            run.reset();
          },
          "Back to the scene's start (state, counters, commands' initial values, guard).")
      .def_property_readonly("time", read_locked([](const Simulation& s) { return s.state().time; }), "t [s]")
      .def_property_readonly("steps_taken", read_locked([](const Simulation& s) { return s.steps_taken(); }))
      .def_property_readonly("at_end", read_locked([](const Simulation& s) { return s.at_end(); }))
      .def_property_readonly("end_time", read_locked([](const Simulation& s) { return s.end_time(); }), "[s]")
      .def_property_readonly("step_size", read_locked([](const Simulation& s) { return s.step_size(); }), "h [s]")
      .def_property_readonly("integrator", read_locked([](const Simulation& s) { return s.integrator_name(); }))
      .def_property_readonly("scene", read_locked([](const Simulation& s) { return s.scene(); }))
      .def_property_readonly("accepts_steering_command",
                             read_locked([](const Simulation& s) { return s.accepts_steering_command(); }))
      .def_property_readonly("accepts_drive_command",
                             read_locked([](const Simulation& s) { return s.accepts_drive_command(); }))
      .def_property_readonly("steering_command", read_locked([](const Simulation& s) { return s.steering_command(); }),
                             "The steering torque in force [N·m].")
      .def_property_readonly("drive_command", read_locked([](const Simulation& s) { return s.drive_command(); }),
                             "The drive torque in force [N·m].");

  python::bind_own_system(m);
}
