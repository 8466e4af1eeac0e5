// birkhoff_cart.simulator: the simulator as a Python module (pybind11, numpy). It translates only:
// scenes come through the core's scene reader (scene_source.h), runs through GuardedRun
// (core/guarded_run.h: the run loop with its accuracy guard that cart_simulate and cart_sim share), and the arrays it returns are
// the core's CartState, Diagnostics and guard values in SI units. The long loops (a batch of steps,
// a run, a time grid) run in C++ with the GIL released, so a Python loop that advances many steps per
// call pays the crossing once. docs/python.md.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "birkhoff_cart/core/accuracy_guard.h"
#include "birkhoff_cart/core/cart_binding/cart_stepper.h"
#include "birkhoff_cart/core/cart_binding/integrator_registry.h"
#include "birkhoff_cart/core/run_summary.h"
#include "birkhoff_cart/core/scene.h"
#include "birkhoff_cart/core/version.h"
#include "birkhoff_cart/core/guarded_run.h"
#include "scene_source.h"

namespace py = pybind11;

namespace birkhoff_cart {
namespace python {
namespace {

/// The columns of a state row, in order, each in SI units (docs/python.md): scene time, the hinge
/// B, heading, steering angle, wheel angles, arc length, quasi-velocities, work and impulse.
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

void translate_exceptions(std::exception_ptr pending) {
  try {
    if (pending) std::rethrow_exception(pending);
  } catch (const SceneError& error) {
    py::object instance = py::reinterpret_steal<py::object>(PyObject_CallFunction(scene_error_type, "s", error.what()));
    if (!instance) return;  // the call set its own error
    instance.attr("key") = error.key();
    instance.attr("file") = error.file();
    PyErr_SetObject(scene_error_type, instance.ptr());
  } catch (const StepError& error) {
    PyErr_SetString(step_error_type, error.what());
  }
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
  m.attr("SceneError") = py::handle(scene_error_type);
  m.attr("StepError") = py::handle(step_error_type);
  py::register_exception_translator(&translate_exceptions);

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

  py::class_<GuardedRun>(m, "Simulation",
                         "A running scene with its accuracy guard, checked where cart_simulate checks it: at the "
                         "start, at every output instant t0 + k/output_rate on the step grid, and at the end.")
      .def(py::init<const Scene&>(), py::arg("scene"), py::call_guard<py::gil_scoped_release>())
      .def("state", [](const GuardedRun& run) { return vector_array(state_row(run.simulation().state())); },
           "The state now, as STATE_FIELDS (SI units).")
      .def("diagnostics", [](const GuardedRun& run) { return vector_array(diagnostics_row(run.simulation())); },
           "Invariants and errors now, as DIAGNOSTIC_FIELDS (SI units; NaN where there is none).")
      .def("statistics", [](const GuardedRun& run) { return statistics_dict(run.simulation().statistics()); })
      .def("accuracy", [](const GuardedRun& run) { return accuracy_dict(run.guard()); },
           "The accuracy guard's verdict: level (OK, WARN, ERROR), summary, and the largest and current value of "
           "each guarded quantity.")
      .def("summary", [](const GuardedRun& run) { return run_summary(run.simulation(), run.guard()); },
           "cart_simulate's summary of the run.")
      .def(
          "step",
          [](GuardedRun& run, py::ssize_t count, const py::object& steering_torque, const py::object& drive_torque,
             bool record) -> py::object {
            if (count < 0) throw py::value_error("count must be >= 0, got " + std::to_string(count));
            const std::size_t n = static_cast<std::size_t>(count);
            std::vector<StepCommands> commands;
            const double steering = read_torque(steering_torque, "steering_torque", n, commands, &StepCommands::steering);
            const double drive = read_torque(drive_torque, "drive_torque", n, commands, &StepCommands::drive);
            if (!std::isnan(steering)) run.simulation().set_steering_command(steering);
            if (!std::isnan(drive)) run.simulation().set_drive_command(drive);
            std::vector<CartState> states;
            {
              py::gil_scoped_release release;
              run.advance(n, commands, record, &states);
            }
            if (!record) return vector_array(state_row(run.simulation().state()));
            std::vector<Row> rows;
            for (const CartState& state : states) rows.push_back(state_row(state));
            return matrix_array(rows, kStateFields.size());
          },
          py::arg("count") = 1, py::arg("steering_torque") = py::none(), py::arg("drive_torque") = py::none(),
          py::arg("record") = false,
          "Up to `count` steps of the run's schedule (fewer at its end). A torque [N·m] given as a number is "
          "commanded now and held (zero-order hold; count=0 only commands), as an array one value per step. "
          "Returns the state after the last step, or with record=True the state after each (count × STATE_FIELDS).")
      .def(
          "run",
          [](GuardedRun& run) {
            {
              py::gil_scoped_release release;
              run.run_to_end();
            }
            return vector_array(state_row(run.simulation().state()));
          },
          "Steps to the run's end; returns the final state.")
      .def(
          "run_to",
          [](GuardedRun& run, const std::vector<double>& times, bool diagnostics) -> py::object {
            std::vector<CartState> states;
            std::vector<Row> diagnostic_rows;
            {
              py::gil_scoped_release release;
              states = run.states_at(times, [&](const Simulation& simulation) {
                if (diagnostics) diagnostic_rows.push_back(diagnostics_row(simulation));
              });
            }
            std::vector<Row> rows;
            for (const CartState& state : states) rows.push_back(state_row(state));
            py::array_t<double> state_array = matrix_array(rows, kStateFields.size());
            if (!diagnostics) return std::move(state_array);
            return py::make_tuple(state_array, matrix_array(diagnostic_rows, kDiagnosticFields.size()));
          },
          py::arg("times"), py::arg("diagnostics") = false,
          "The states at `times` [s] (increasing, from now to the end), advancing the run to the last; with "
          "diagnostics=True also the diagnostics there: (states, diagnostics). A member with its own steps (a step "
          "control, dopri5) gives any instant from its dense output; a member at fixed steps the step schedule's.")
      .def("reset", &GuardedRun::reset, "Back to the scene's start (state, counters, commands' initial values, guard).")
      .def_property_readonly("time", [](const GuardedRun& run) { return run.simulation().state().time; }, "t [s]")
      .def_property_readonly("steps_taken", [](const GuardedRun& run) { return run.simulation().steps_taken(); })
      .def_property_readonly("at_end", [](const GuardedRun& run) { return run.simulation().at_end(); })
      .def_property_readonly("end_time", [](const GuardedRun& run) { return run.simulation().end_time(); }, "[s]")
      .def_property_readonly("step_size", [](const GuardedRun& run) { return run.simulation().step_size(); }, "h [s]")
      .def_property_readonly("integrator", [](const GuardedRun& run) { return run.simulation().integrator_name(); })
      .def_property_readonly("scene", [](const GuardedRun& run) { return run.simulation().scene(); })
      .def_property_readonly("accepts_steering_command",
                             [](const GuardedRun& run) { return run.simulation().accepts_steering_command(); })
      .def_property_readonly("accepts_drive_command",
                             [](const GuardedRun& run) { return run.simulation().accepts_drive_command(); })
      .def_property_readonly("steering_command", [](const GuardedRun& run) { return run.simulation().steering_command(); },
                             "The steering torque in force [N·m].")
      .def_property_readonly("drive_command", [](const GuardedRun& run) { return run.simulation().drive_command(); },
                             "The drive torque in force [N·m].");
}
