// The own-system face of the Python module (own_system_bindings.h).
#include "own_system_bindings.h"

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "birkhoff_cart/core/examples/chaplygin_sleigh.h"
#include "birkhoff_cart/core/integrators/system_integration.h"
#include "event_specs.h"
#include "python_system.h"

namespace birkhoff_cart {
namespace python {
namespace {

/// The dimensions of z a Python system may have (one instantiation of every member each).
constexpr int kSupportedDimensions[] = {2, 4};

/// simulator.BirkhoffianSystem: the callables and the dimension, checked once.
struct UserSystem {
  int dimension = 0;
  SystemFunctions functions;
};

/// simulator.ChaplyginSleigh: the C++ example system (identity chart), for comparison with a Python
/// system and for the price of a callback.
struct SleighSystem {
  ChaplyginSleighParameters parameters;
};

/// simulator.integrate's result, shaped like scipy's solve_ivp result.
struct SystemSolution {
  py::array_t<double> t;  ///< (n,) [s]
  py::array_t<double> y;  ///< (dimension, n)
  py::list t_events;      ///< per event: the times of its crossings [s]
  py::list y_events;      ///< per event: (crossings, dimension) states there
  std::uint64_t nfev = 0;
  py::object njev = py::none();
  std::uint64_t nsteps = 0;
  std::uint64_t nrejected = 0;
  std::uint64_t newton_iterations = 0;
  int status = 0;
  std::string message;
  std::string integrator;
  std::string step_control;
  bool success() const { return status >= 0; }
};

py::object checked_callable(const py::object& value, const char* name, bool required) {
  if (value.is_none()) {
    if (required) throw py::type_error(std::string(name) + " is required: a callable f(z, t)");
    return value;
  }
  if (!PyCallable_Check(value.ptr())) {
    throw py::type_error(std::string(name) + " must be a callable f(z, t), got " + py::repr(value).cast<std::string>());
  }
  return value;
}

UserSystem make_user_system(int dimension, const py::object& birkhoffian_gradient, const py::object& structure_matrix,
                            const py::object& birkhoff_functions_time_derivative,
                            const py::object& non_birkhoffian_force, const py::object& darboux_chart,
                            const py::object& jacobian) {
  bool supported = false;
  for (int d : kSupportedDimensions) supported = supported || d == dimension;
  if (!supported) {
    throw py::value_error("dimension must be 2 or 4 (z = (q, p) of one or two degrees of freedom), got " +
                          std::to_string(dimension));
  }
  UserSystem system;
  system.dimension = dimension;
  SystemFunctions& f = system.functions;
  f.structure_matrix = checked_callable(structure_matrix, "structure_matrix", false);
  f.birkhoff_functions_time_derivative =
      checked_callable(birkhoff_functions_time_derivative, "birkhoff_functions_time_derivative", false);
  f.non_birkhoffian_force = checked_callable(non_birkhoffian_force, "non_birkhoffian_force", false);
  f.jacobian = checked_callable(jacobian, "jacobian", false);
  f.to_darboux = f.from_darboux = f.darboux_rates = py::none();
  if (!darboux_chart.is_none()) {
    const py::tuple chart = py::tuple(darboux_chart);
    if (chart.size() != 3) {
      throw py::value_error("darboux_chart must be (to_darboux, from_darboux, darboux_rates), three callables");
    }
    f.to_darboux = checked_callable(chart[0], "darboux_chart[0] (to_darboux)", true);
    f.from_darboux = checked_callable(chart[1], "darboux_chart[1] (from_darboux)", true);
    f.darboux_rates = checked_callable(chart[2], "darboux_chart[2] (darboux_rates)", true);
    f.birkhoffian_gradient = checked_callable(birkhoffian_gradient, "birkhoffian_gradient", false);
  } else {
    f.birkhoffian_gradient = checked_callable(birkhoffian_gradient, "birkhoffian_gradient", true);
  }
  return system;
}

SystemStepControl control_from(const std::string& name) {
  if (name == "fixed") return SystemStepControl::kFixed;
  if (name == "adaptive") return SystemStepControl::kAdaptive;
  if (name == "reversible") return SystemStepControl::kReversible;
  throw py::value_error("step_control must be 'fixed', 'adaptive' or 'reversible', got '" + name + "'");
}

/// The events of integrate(), read as solve() reads them (event_specs.h); a system's run stops at an
/// event's first crossing, so `terminal` is True or False (or 0 or 1) here.
template <class System>
std::vector<SystemEvent<System>> events_from(const py::object& given) {
  std::vector<SystemEvent<System>> events;
  const std::vector<EventSpec> specs = read_event_specs(given);
  for (std::size_t k = 0; k < specs.size(); ++k) {
    if (specs[k].terminal_after > 1) {
      throw py::value_error("events[" + std::to_string(k) + "].terminal must be True or False for integrate() (it "
                            "stops at the first crossing), got " + std::to_string(specs[k].terminal_after));
    }
    const py::object function = specs[k].g;
    SystemEvent<System> event;
    event.terminal = specs[k].terminal_after == 1;
    event.direction = specs[k].direction > 0.0 ? 1 : (specs[k].direction < 0.0 ? -1 : 0);
    event.function = [function, k](double t, const StateVector<System, double>& z) {
      py::array_t<double> state(System::kDimension);
      for (int i = 0; i < System::kDimension; ++i) state.mutable_at(i) = z(i);
      const py::object value = function(t, state);
      try {
        return value.cast<double>();
      } catch (const py::cast_error&) {
        throw py::type_error("events[" + std::to_string(k) + "] must return a number, got " +
                             py::repr(value).cast<std::string>());
      }
    };
    events.push_back(std::move(event));
  }
  return events;
}

template <class System>
SystemSolution solve(System& system, const py::array_t<double, py::array::c_style | py::array::forcecast>& z0,
                     double t0, double t1, const SystemRunRequest& request, const std::uint64_t* jacobians,
                     const py::object& events_given) {
  constexpr int n = System::kDimension;
  const std::vector<SystemEvent<System>> events = events_from<System>(events_given);
  if (z0.ndim() != 1 || z0.shape(0) != n) {
    throw py::value_error("z0 must hold " + std::to_string(n) + " numbers, got shape " +
                          py::repr(py::cast(std::vector<py::ssize_t>(z0.shape(), z0.shape() + z0.ndim())))
                              .cast<std::string>());
  }
  StateVector<System, double> start;
  for (int i = 0; i < n; ++i) start(i) = z0.at(i);
  SystemRunResult<System> run;
  try {
    run = integrate_system(system, start, t0, t1, request, events);
  } catch (const std::invalid_argument& error) {
    throw py::value_error(error.what());
  }
  SystemSolution solution;
  const auto count = static_cast<py::ssize_t>(run.times.size());
  solution.t = py::array_t<double>(count);
  solution.y = py::array_t<double>({static_cast<py::ssize_t>(n), count});
  for (py::ssize_t k = 0; k < count; ++k) {
    solution.t.mutable_at(k) = run.times[static_cast<std::size_t>(k)];
    for (int i = 0; i < n; ++i) solution.y.mutable_at(i, k) = run.states[static_cast<std::size_t>(k)](i);
  }
  solution.nfev = run.statistics.rhs_evaluations;
  if (jacobians != nullptr) solution.njev = py::int_(*jacobians);
  solution.nsteps = run.statistics.internal_steps;
  solution.nrejected = run.statistics.rejected_steps;
  solution.newton_iterations = run.statistics.newton_iterations_total;
  for (std::size_t k = 0; k < events.size(); ++k) {
    std::vector<double> times;
    std::vector<const StateVector<System, double>*> states;
    for (const SystemEventCrossing<System>& crossing : run.crossings) {
      if (crossing.event != k) continue;
      times.push_back(crossing.time);
      states.push_back(&crossing.state);
    }
    py::array_t<double> event_times(static_cast<py::ssize_t>(times.size()));
    py::array_t<double> event_states({static_cast<py::ssize_t>(times.size()), static_cast<py::ssize_t>(n)});
    for (std::size_t c = 0; c < times.size(); ++c) {
      event_times.mutable_at(static_cast<py::ssize_t>(c)) = times[c];
      for (int i = 0; i < n; ++i) event_states.mutable_at(static_cast<py::ssize_t>(c), i) = (*states[c])(i);
    }
    solution.t_events.append(event_times);
    solution.y_events.append(event_states);
  }
  solution.status = run.finished ? (run.terminal_event ? 1 : 0) : -1;
  solution.message = run.message;
  solution.integrator = request.integrator;
  return solution;
}

template <int Dimension>
SystemSolution solve_user(const UserSystem& user, const py::array_t<double, py::array::c_style | py::array::forcecast>& z0,
                          double t0, double t1, const SystemRunRequest& request, const py::object& events) {
  std::uint64_t jacobians = 0;
  SystemFunctions functions = user.functions;
  functions.jacobian_evaluations = &jacobians;
  if (functions.to_darboux.is_none()) {
    PythonBirkhoffianSystem<Dimension, true> system(functions);
    return solve(system, z0, t0, t1, request, &jacobians, events);
  }
  PythonBirkhoffianSystem<Dimension, false> system(functions);
  return solve(system, z0, t0, t1, request, &jacobians, events);
}

SystemSolution integrate(const py::object& system, const py::array_t<double, py::array::c_style | py::array::forcecast>& z0,
                         const std::pair<double, double>& t_span, const std::string& integrator,
                         const py::object& step_size, const std::string& step_control, const py::object& tolerance,
                         std::uint64_t max_steps, const py::object& events) {
  // Every step is a state of the result: the work limit is also its memory bound, at most the module's
  // MAX_RECORDED_STATES (read from the module, so that one constant holds for every call).
  const auto recorded_limit = py::module_::import("birkhoff_cart.simulator").attr("MAX_RECORDED_STATES").cast<std::uint64_t>();
  if (max_steps < 1 || max_steps > recorded_limit) {
    throw py::value_error("max_steps must be 1 ... MAX_RECORDED_STATES = " + std::to_string(recorded_limit) +
                          " (every step is a state of the result), got " + std::to_string(max_steps));
  }
  SystemRunRequest request;
  request.integrator = integrator;
  request.control = control_from(step_control);
  request.max_steps = max_steps;
  if (!step_size.is_none()) request.step_size = step_size.cast<double>();
  if (!tolerance.is_none()) request.tolerance = tolerance.cast<double>();
  if (request.control == SystemStepControl::kFixed) {
    if (step_size.is_none()) throw py::value_error("step_control 'fixed' needs step_size [s]");
    if (!tolerance.is_none()) {
      throw py::value_error("tolerance is for step_control 'adaptive' or 'reversible', not for fixed steps");
    }
  } else if (tolerance.is_none()) {
    throw py::value_error("step_control '" + step_control + "' needs a tolerance");
  }
  SystemSolution solution;
  if (py::isinstance<SleighSystem>(system)) {
    AutonomousChaplyginSleigh sleigh(system.cast<const SleighSystem&>().parameters);
    solution = solve(sleigh, z0, t_span.first, t_span.second, request, nullptr, events);
  } else if (py::isinstance<UserSystem>(system)) {
    const UserSystem& user = system.cast<const UserSystem&>();
    solution = user.dimension == 2 ? solve_user<2>(user, z0, t_span.first, t_span.second, request, events)
                                   : solve_user<4>(user, z0, t_span.first, t_span.second, request, events);
  } else {
    throw py::type_error("system must be a BirkhoffianSystem or a ChaplyginSleigh, got " +
                         py::repr(system).cast<std::string>());
  }
  solution.step_control = step_control;
  return solution;
}

}  // namespace

void bind_own_system(py::module_& m) {
  py::class_<UserSystem>(m, "BirkhoffianSystem",
                         "Your own Birkhoffian system K(z,t) z' = grad B(z,t) + dR/dt(z,t) + Lambda(z,t) (docs/"
                         "birkhoffian.md eq. (B.1)) from Python callables f(z, t) on numpy arrays, for integrate(). "
                         "dimension: 2 or 4. structure_matrix K defaults to the canonical [[0, -I], [I, 0]] (z = (q, "
                         "p)); dR/dt and Lambda default to 0. Without darboux_chart the members step in z itself "
                         "(K-symplectic where K is constant); with darboux_chart = (to_darboux, from_darboux, "
                         "darboux_rates) they step in that chart. jacobian(w, t) = dw'/dw, else central differences.")
      .def(py::init(&make_user_system), py::arg("dimension"), py::arg("birkhoffian_gradient") = py::none(),
           py::arg("structure_matrix") = py::none(), py::arg("birkhoff_functions_time_derivative") = py::none(),
           py::arg("non_birkhoffian_force") = py::none(), py::arg("darboux_chart") = py::none(),
           py::arg("jacobian") = py::none())
      .def_property_readonly("dimension", [](const UserSystem& s) { return s.dimension; })
      .def_property_readonly("has_darboux_chart", [](const UserSystem& s) { return !s.functions.to_darboux.is_none(); })
      .def("__repr__", [](const UserSystem& s) {
        return "<BirkhoffianSystem: dimension " + std::to_string(s.dimension) +
               (s.functions.to_darboux.is_none() ? ", identity chart>" : ", own Darboux chart>");
      });
  py::class_<SleighSystem>(m, "ChaplyginSleigh",
                           "The Chaplygin sleigh of the C++ core (examples/chaplygin_sleigh.h, autonomous form), "
                           "z = (arc length [m], heading [rad], m v [kg m/s], J omega [kg m^2/s]): the same system "
                           "as a C++ model, to compare a Python system with and to price a callback.")
      .def(py::init([](double mass, double inertia_at_centre, double centre_offset) {
             if (!(mass > 0.0) || !(inertia_at_centre > 0.0) || !std::isfinite(centre_offset)) {
               throw py::value_error("ChaplyginSleigh needs mass > 0 kg, inertia_at_centre > 0 kg m^2 and a finite "
                                     "centre_offset [m]");
             }
             SleighSystem sleigh;
             sleigh.parameters.mass = mass;
             sleigh.parameters.inertia_at_centre = inertia_at_centre;
             sleigh.parameters.centre_offset = centre_offset;
             return sleigh;
           }),
           py::arg("mass") = 2.0, py::arg("inertia_at_centre") = 0.5, py::arg("centre_offset") = 0.3)
      .def_property_readonly("dimension", [](const SleighSystem&) { return 4; });
  py::class_<SystemSolution>(m, "SystemSolution",
                             "integrate()'s result, shaped like scipy's solve_ivp result: t (n,), y (dimension, n) "
                             "on the member's own steps (t0 first, t1 or a terminal event last), t_events and "
                             "y_events (per event its crossings), nfev, njev, nsteps, nrejected, status (0: reached "
                             "t1, 1: a terminal event, -1: a step failed; y holds the states before it), message, "
                             "success.")
      .def_readonly("t_events", &SystemSolution::t_events)
      .def_readonly("y_events", &SystemSolution::y_events)
      .def_readonly("t", &SystemSolution::t)
      .def_readonly("y", &SystemSolution::y)
      .def_readonly("nfev", &SystemSolution::nfev)
      .def_readonly("njev", &SystemSolution::njev)
      .def_readonly("nsteps", &SystemSolution::nsteps)
      .def_readonly("nrejected", &SystemSolution::nrejected)
      .def_readonly("newton_iterations", &SystemSolution::newton_iterations)
      .def_readonly("status", &SystemSolution::status)
      .def_readonly("message", &SystemSolution::message)
      .def_readonly("integrator", &SystemSolution::integrator)
      .def_readonly("step_control", &SystemSolution::step_control)
      .def_property_readonly("success", &SystemSolution::success)
      .def("__repr__", [](const SystemSolution& s) {
        return "<SystemSolution " + s.integrator + " (" + s.step_control + "): " + std::to_string(s.t.shape(0)) +
               " points, nfev " + std::to_string(s.nfev) + ", status " + std::to_string(s.status) + ": " + s.message + ">";
      });
  m.def("integrate", &integrate, py::arg("system"), py::arg("z0"), py::arg("t_span"),
        py::arg("integrator") = "birkhoff_gauss8", py::arg("step_size") = py::none(),
        py::arg("step_control") = "fixed", py::arg("tolerance") = py::none(), py::arg("max_steps") = 1000000,
        py::arg("events") = py::none(),
        "Integrates a BirkhoffianSystem (or the C++ ChaplyginSleigh) from z0 at t_span[0] to t_span[1] [s] with a "
        "Birkhoffian member: at fixed steps of step_size, or under step_control 'adaptive' or 'reversible' "
        "(birkhoff_gauss4/6/8; reversible only in the identity chart) for `tolerance`, the error at t1 in the "
        "weights max(1, |z_i|). events: a callable g(t, z) or a list of them, with optional attributes terminal "
        "and direction as in scipy's solve_ivp; their crossings are located on the member's own step to 1e-13 "
        "relative. Returns a SystemSolution. Bad requests raise ValueError naming them; an exception raised by a "
        "callable passes through.");
  m.attr("BIRKHOFFIAN_MEMBERS") = birkhoffian_member_names();
}

}  // namespace python
}  // namespace birkhoff_cart
