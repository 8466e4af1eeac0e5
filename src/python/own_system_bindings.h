// simulator.BirkhoffianSystem, simulator.ChaplyginSleigh and simulator.integrate: a user's own
// Birkhoffian system integrated by the Birkhoffian members (docs/python.md, "Your own Birkhoffian
// system"; src/python/python_system.h, core/integrators/system_integration.h).
#pragma once

#include <pybind11/pybind11.h>

namespace birkhoff_cart {
namespace python {

/// Adds the own-system classes and integrate() to the module.
void bind_own_system(pybind11::module_& module);

}  // namespace python
}  // namespace birkhoff_cart
