// work_precision: the reference states a scene's errors are measured against, and the second
// setting each is checked against (the study compares the two at every checkpoint).
//
//  - jackknife_whirl (free cart): Boost.Odeint in extended precision (long double, 64-bit
//    mantissa, ε = 1.1e-19) on the same right-hand side instantiated for S = long double:
//    controlled runge_kutta_fehlberg78 at tolerance 1e-18 (the reference) against bulirsch_stoer
//    at 1e-18 (the independent method it must agree with), compared at every checkpoint. A second
//    setting of rkf78 is no check: its error estimate, (41/840)(k1 + k11 − k12 − k13) h, compares
//    stages at the two ends of the step only, and on a steady whirl a step of a whole number of
//    turns makes them equal — both settings then stride over the turns together, wrong by hundreds
//    of metres (near_jackknife over 2000 s), while the extrapolation's estimate is not fooled.
//  - the short forced scenes: our dopri5 at 1e-13 against 1e-12 (double).
//  - paper_special: the closed form.
#pragma once

#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include "bench_scene.h"
#include "birkhoff_cart/core/run/simulation.h"
#include "odeint_peers.h"
#include "ours.h"

namespace birkhoff_cart {
namespace work_precision {

constexpr double kDopri5ReferenceTolerance = 1e-13;       // double reference of the forced scenes [-]
constexpr double kDopri5ReferenceCheckTolerance = 1e-12;  // its check [-]
constexpr long double kExtendedReferenceTolerance = 1e-18L;  // long double rkf78 [-]
constexpr long double kExtendedCheckTolerance = 1e-18L;      // its check, long double bulirsch_stoer [-]

/// A reference trajectory: the state at each checkpoint, with its cost.
struct ReferenceRun {
  std::string name;
  std::vector<CartState> states;
  std::uint64_t rhs_evaluations = 0;
  double wall = NAN;  ///< [s]
};

/// Odeint in long double ("rkf78" or "bulirsch_stoer") on the autonomous Birkhoffian form.
inline ReferenceRun extended_precision_run(const BenchScene& bench, const std::string& stepper_name,
                                           long double tolerance) {
  namespace odeint = boost::numeric::odeint;
  using S = long double;
  using Joint = JointState<S>;
  if (bench.scene.integrator.birkhoffian_form != BirkhoffianForm::kAutonomous) {
    throw std::invalid_argument(std::string("extended-precision reference: autonomous form only, got '") +
                                to_string(bench.scene.integrator.birkhoffian_form) + "'");
  }
  const Simulation holder(configured(bench.scene, "rk4", 0.1, 1e-10));
  const CartAutonomousBirkhoffian system(holder.model(), holder.effects());
  ReferenceRun run;
  char name[96];
  std::snprintf(name, sizeof name, "long_double_%s_tol_%.0Le", stepper_name.c_str(), tolerance);
  run.name = name;
  const JointRates<CartAutonomousBirkhoffian, S> rates{&system, &run.rhs_evaluations};
  Joint x = joint_start<CartAutonomousBirkhoffian, S>(system, bench.scene.initial_state);
  const S t0 = bench.scene.initial_state.time;
  const auto observe = [](const Joint&, S) {};
  const auto keep = [&](std::size_t, const Joint& state, S t) {
    run.states.push_back(joint_to_cart_state(system, state, static_cast<double>(t)));
  };
  const double w0 = wall_seconds();
  if (stepper_name == "rkf78") {
    auto stepper = deterministic_controlled(tolerance, tolerance, odeint::runge_kutta_fehlberg78<Joint, S>());
    integrate_through_checkpoints(stepper, rates, x, t0, bench.checkpoint_times, S(1e-3), observe, keep);
  } else if (stepper_name == "bulirsch_stoer") {
    odeint::bulirsch_stoer<Joint, S> stepper(tolerance, tolerance);
    integrate_through_checkpoints(stepper, rates, x, t0, bench.checkpoint_times, S(1e-3), observe, keep);
  } else {
    throw std::invalid_argument("extended-precision reference: unknown stepper '" + stepper_name + "'");
  }
  run.wall = wall_seconds() - w0;
  return run;
}

/// Our dopri5 (double) at `tolerance`, states at the checkpoints (multiples of 0.1 s).
inline ReferenceRun dopri5_run(const BenchScene& bench, double tolerance) {
  ReferenceRun run;
  char name[64];
  std::snprintf(name, sizeof name, "dopri5_tol_%.0e", tolerance);
  run.name = name;
  const std::uint64_t steps = step_count(bench.scene.duration, kSampleInterval);
  const std::vector<std::uint64_t> checkpoints = checkpoint_steps(bench, steps);
  Simulation sim(configured(bench.scene, "dopri5", bench.scene.duration / static_cast<double>(steps), tolerance));
  const double w0 = wall_seconds();
  std::size_t next = 0;
  for (std::uint64_t k = 1; k <= steps; ++k) {
    sim.step();
    while (next < checkpoints.size() && checkpoints[next] < k) {
      run.states.push_back(CartState{});  // a checkpoint that is no multiple of 0.1 s
      run.states.back().x = run.states.back().y = NAN;
      ++next;
    }
    if (next < checkpoints.size() && checkpoints[next] == k) {
      run.states.push_back(sim.state());
      ++next;
    }
  }
  run.wall = wall_seconds() - w0;
  run.rhs_evaluations = sim.statistics().rhs_evaluations;
  return run;
}

/// The reference of `kind` ("extended_precision" or "dopri5") at the checkpoints, or with `check`
/// the run it is checked against: an independent method for extended precision (long double
/// bulirsch_stoer against rkf78), a second setting for dopri5 (1e-12 against 1e-13). The study
/// accepts the reference for a goal only where the two agree to a tenth of it.
inline ReferenceRun reference_run(const BenchScene& bench, const std::string& kind, bool check) {
  if (kind == "extended_precision") {
    return check ? extended_precision_run(bench, "bulirsch_stoer", kExtendedCheckTolerance)
                 : extended_precision_run(bench, "rkf78", kExtendedReferenceTolerance);
  }
  if (kind == "dopri5") return dopri5_run(bench, check ? kDopri5ReferenceCheckTolerance : kDopri5ReferenceTolerance);
  throw std::invalid_argument("unknown reference kind '" + kind + "'");
}

}  // namespace work_precision
}  // namespace birkhoff_cart
