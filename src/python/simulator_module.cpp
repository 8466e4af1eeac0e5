// birkhoff_cart.simulator: the simulator as a Python module (pybind11, numpy). It translates only:
// scenes come through the core's scene reader (scene_source.h), runs through GuardedRun
// (core/guarded_run.h: the run loop with its accuracy guard that cart_simulate and cart_sim share), and the arrays it returns are
// the core's CartState, Diagnostics and guard values in SI units. The long loops (a batch of steps,
// a run, a time grid) run in C++ with the GIL released, so a Python loop that advances many steps per
// call pays the crossing once; calls on one Simulation from several threads take its lock one at a
// time, waiting for it without the GIL. docs/python.md.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>
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
  counts["local_error_estimate_max"] = statistics.local_error_estimate_max;
  counts["local_error_estimate_sum"] = statistics.local_error_estimate_sum;
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
