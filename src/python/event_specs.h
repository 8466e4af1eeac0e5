// solve_ivp's event callables as the module reads them, for simulator.solve (the cart) and
// simulator.integrate (a system of your own): a callable g(t, state), or a sequence of them, each
// with the optional attributes `direction` (a number: > 0 only − to +, < 0 only + to −, 0 both) and
// `terminal` (a bool, or the count of crossings after which the run stops). Wrong types are a
// TypeError naming events[i] and the attribute.
#pragma once

#include <pybind11/pybind11.h>

#include <cstdint>
#include <string>
#include <vector>

namespace birkhoff_cart {
namespace python {

/// One event callable and its attributes.
struct EventSpec {
  pybind11::object g;
  double direction = 0.0;            ///< > 0: only − to +; < 0: only + to −; 0: both
  std::uint64_t terminal_after = 0;  ///< stop at this crossing (0: never)
};

inline std::vector<EventSpec> read_event_specs(const pybind11::object& events) {
  namespace py = pybind11;
  std::vector<EventSpec> specs;
  if (events.is_none()) return specs;
  std::vector<py::object> given;
  if (py::isinstance<py::str>(events) || py::isinstance<py::bytes>(events)) {
    throw py::type_error("events must be a callable g(t, state) or a sequence of them, got the text " +
                         std::string(py::repr(events)) +
                         " (texts like 'chi=0.3,rising' are cart_simulate's --event and cart_sim's ~events)");
  }
  if (PyCallable_Check(events.ptr())) {
    given.push_back(events);
  } else {
    for (const py::handle item : py::iter(events)) given.push_back(py::reinterpret_borrow<py::object>(item));
  }
  for (std::size_t i = 0; i < given.size(); ++i) {
    const py::object& g = given[i];
    if (!PyCallable_Check(g.ptr())) {
      throw py::type_error("events[" + std::to_string(i) + "] must be a callable g(t, state), got " +
                           std::string(py::repr(g)));
    }
    EventSpec spec;
    spec.g = g;
    const py::object direction = py::getattr(g, "direction", py::float_(0.0));
    const py::object terminal = py::getattr(g, "terminal", py::bool_(false));
    if (py::isinstance<py::str>(direction) || py::isinstance<py::bytes>(direction) ||
        !PyNumber_Check(direction.ptr())) {
      throw py::type_error("events[" + std::to_string(i) + "].direction must be a number, got " +
                           std::string(py::repr(direction)));
    }
    spec.direction = py::float_(direction);
    if (py::isinstance<py::bool_>(terminal)) {
      spec.terminal_after = terminal.cast<bool>() ? 1 : 0;
    } else if (py::isinstance<py::int_>(terminal)) {
      const long long count = terminal.cast<long long>();
      if (count < 0) throw py::value_error("events[" + std::to_string(i) + "].terminal must be >= 0");
      spec.terminal_after = static_cast<std::uint64_t>(count);
    } else {
      throw py::type_error("events[" + std::to_string(i) + "].terminal must be a bool or an int (solve_ivp's)");
    }
    specs.push_back(std::move(spec));
  }
  return specs;
}

}  // namespace python
}  // namespace birkhoff_cart
