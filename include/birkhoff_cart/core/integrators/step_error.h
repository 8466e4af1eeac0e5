// How a step of any integrator reports that it cannot be taken: StepError, and the collocation
// members' one way to throw it (fail_collocation_step). Knows no system: the generic numerics
// (this folder) report through it, and cart_stepper.h passes it on to the simulation.
#pragma once

#include <sstream>
#include <stdexcept>

namespace birkhoff_cart {

/// A step that could not be taken (Newton did not converge, non-finite value, singular matrix).
class StepError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Throws StepError("Gauss collocation stage solve <what> in the step from t = <time> s after
/// <iterations> iterations"): a stage solve that does not converge, a non-finite value or a
/// singular Newton matrix.
[[noreturn]] inline void fail_collocation_step(const char* what, double time, int iterations) {
  std::ostringstream message;
  message.precision(17);
  message << "Gauss collocation stage solve " << what << " in the step from t = " << time << " s after " << iterations
          << " iterations";
  throw StepError(message.str());
}

}  // namespace birkhoff_cart
