// Boost.Odeint's controlled Runge–Kutta steppers with a step-size factor that has the same bits on
// every x86-64 CPU. odeint's default_step_adjuster takes the factor 0.9·err^(−1/q) from std::pow,
// whose result depends on the CPU glibc runs on (FMA or not; for long double the x87's own
// transcendental instructions); one differing bit in a step size makes a different run. This
// adjuster is odeint's rule unchanged, with the power from deterministic_math.h (in double: the
// factor needs a few digits, not the last one of a long double). docs/developing.md, "Figures that
// hold on every machine".
//
// Use DeterministicControlled<Stepper, Checker> where odeint's controlled_runge_kutta<Stepper,
// Checker> would stand, and deterministic_controlled(abs, rel, stepper) for make_controlled.
// Boost.Odeint's Bulirsch–Stoer steppers keep their own std::pow (it cannot be replaced from outside).
#pragma once

#include <algorithm>
#include <boost/numeric/odeint.hpp>

#include "birkhoff_cart/core/integrators/deterministic_math.h"

namespace birkhoff_cart {

template <class Value, class Time = Value>
class DeterministicStepAdjuster : public boost::numeric::odeint::default_step_adjuster<Value, Time> {
  using Base = boost::numeric::odeint::default_step_adjuster<Value, Time>;

 public:
  using Base::Base;

  /// dt · max(0.9 err^(−1/(q−1)), 1/5) after a rejected step of error ratio err (odeint's rule) [s].
  Time decrease_step(Time dt, const Value error, const int error_order) const {
    dt *= std::max(Value(Value(9) / Value(10) * power(error, Value(-1) / (error_order - 1))), Value(Value(1) / Value(5)));
    if (this->m_max_dt != Time(0)) dt = boost::numeric::odeint::detail::min_abs(dt, this->m_max_dt);
    return dt;
  }

  /// dt · 0.9 max(err, 5^(−p))^(−1/p) after an accepted step with err < 1/2, else dt (odeint's rule) [s].
  Time increase_step(Time dt, Value error, const int stepper_order) const {
    if (error < Value(0.5)) {
      error = std::max(power(Value(5), -Value(stepper_order)), error);
      dt *= Value(9) / Value(10) * power(error, Value(-1) / stepper_order);
      if (this->m_max_dt != Time(0)) dt = boost::numeric::odeint::detail::min_abs(dt, this->m_max_dt);
    }
    return dt;
  }

 private:
  static Value power(Value base, Value exponent) {
    return Value(deterministic::pow(static_cast<double>(base), static_cast<double>(exponent)));
  }
};

/// odeint's controlled_runge_kutta<Stepper, Checker> with DeterministicStepAdjuster.
template <class Stepper,
          class Checker = boost::numeric::odeint::default_error_checker<
              typename Stepper::value_type, typename Stepper::algebra_type, typename Stepper::operations_type>>
using DeterministicControlled =
    boost::numeric::odeint::controlled_runge_kutta<Stepper, Checker,
                                                   DeterministicStepAdjuster<typename Stepper::value_type,
                                                                             typename Stepper::time_type>>;

/// odeint's make_controlled(abs, rel, stepper) with DeterministicStepAdjuster [-].
template <class Stepper>
DeterministicControlled<Stepper> deterministic_controlled(typename Stepper::value_type absolute,
                                                          typename Stepper::value_type relative, const Stepper& stepper) {
  using Checker = typename DeterministicControlled<Stepper>::error_checker_type;
  using Adjuster = typename DeterministicControlled<Stepper>::step_adjuster_type;
  return DeterministicControlled<Stepper>(Checker(absolute, relative), Adjuster(), stepper);
}

}  // namespace birkhoff_cart
