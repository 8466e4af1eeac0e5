// The one way a collocation step reports that it cannot be taken (a stage solve that does not
// converge, a non-finite value, a singular Newton matrix): a StepError naming what failed and where.
#pragma once

#include <sstream>

#include "birkhoff_cart/core/integrators/cart_stepper.h"

namespace birkhoff_cart {

/// Throws StepError("Gauss collocation stage solve <what> in the step from t = <time> s after
/// <iterations> iterations").
[[noreturn]] inline void fail_collocation_step(const char* what, double time, int iterations) {
  std::ostringstream message;
  message.precision(17);
  message << "Gauss collocation stage solve " << what << " in the step from t = " << time << " s after " << iterations
          << " iterations";
  throw StepError(message.str());
}

}  // namespace birkhoff_cart
