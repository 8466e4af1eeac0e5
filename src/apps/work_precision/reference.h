// work_precision: the reference states a scene's errors are measured against, and how far two
// independent reference settings disagree (reference_check.csv).
//
//  - jackknife_whirl (free cart): Boost.Odeint in extended precision (long double, 64-bit
//    mantissa, ε = 1.1e-19) on the same right-hand side instantiated for S = long double:
//    controlled runge_kutta_fehlberg78 at tolerance 1e-18 (the reference) against rkf78 at 1e-17
//    (the second setting it must agree with), bulirsch_stoer at 1e-18 (an independent method)
//    and our dopri5 at 1e-13 (the former reference), compared at every checkpoint. Computed
//    once for the longest horizon; the shorter one takes its prefix.
//  - the short forced scenes: our dopri5 at 1e-13 against 1e-12 (double), as before.
//  - paper_special: the closed form.
#pragma once

#include <cstdio>
#include <string>
#include <vector>

#include "bench_scene.h"
#include "birkhoff_cart/core/simulation.h"
#include "odeint_peers.h"
#include "ours.h"

namespace birkhoff_cart {
namespace work_precision {

constexpr double kDopri5ReferenceTolerance = 1e-13;       // double reference of the forced scenes [-]
constexpr double kDopri5ReferenceCheckTolerance = 1e-12;  // its check [-]
constexpr long double kExtendedReferenceTolerance = 1e-18L;  // long double rkf78 and bulirsch_stoer [-]
constexpr long double kExtendedCheckTolerance = 1e-17L;      // long double rkf78 check [-]

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
  if (bench.scene.integrator.birkhoffian_form != "autonomous") {
    throw std::invalid_argument("extended-precision reference: autonomous form only, got '" +
                                bench.scene.integrator.birkhoffian_form + "'");
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
    auto stepper = odeint::make_controlled(tolerance, tolerance, odeint::runge_kutta_fehlberg78<Joint, S>());
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

/// Writes one reference_check.csv row per (check run, checkpoint): its distance from the reference.
inline void write_reference_check(std::FILE* check, const BenchScene& bench, const ReferenceRun& reference,
                                  const ReferenceRun& other) {
  for (std::size_t j = 0; j < bench.checkpoint_times.size(); ++j) {
    const CartState& a = reference.states[j];
    const CartState& b = other.states[j];
    std::fprintf(check, "%s,%s,%s,%.9g,%.3e,%.3e,%.3e,%llu,%.2f,%llu,%.2f\n", bench.label.c_str(),
                 reference.name.c_str(), other.name.c_str(), bench.checkpoint_times[j], position_distance(a, b),
                 std::abs(heading_difference(a, b)), std::abs(a.arc_length - b.arc_length),
                 static_cast<unsigned long long>(reference.rhs_evaluations), reference.wall,
                 static_cast<unsigned long long>(other.rhs_evaluations), other.wall);
  }
  std::fflush(check);
}

inline void write_reference_check_header(std::FILE* check) {
  std::fprintf(check,
               "scene,reference,check,t,position_difference_m,heading_difference_rad,arc_length_difference_m,"
               "reference_rhs_evaluations,reference_wall_s,check_rhs_evaluations,check_wall_s\n");
}

/// A reference trajectory with the runs that check it, at a list of times from the start [s].
struct ReferenceSet {
  std::vector<double> times;
  ReferenceRun reference;
  std::vector<ReferenceRun> checks;  ///< checks.front() is the setting the reference must agree with
};

/// jackknife_whirl's reference (see the top of this file) at `times` (from the start [s]); the
/// scenes that share its initial state and differ only in duration take their prefix.
inline ReferenceSet extended_precision_reference(const BenchScene& longest, const std::vector<double>& times) {
  BenchScene bench = longest;
  bench.checkpoint_times = times;
  ReferenceSet set;
  set.times = times;
  set.reference = extended_precision_run(bench, "rkf78", kExtendedReferenceTolerance);
  set.checks.push_back(extended_precision_run(bench, "rkf78", kExtendedCheckTolerance));
  set.checks.push_back(extended_precision_run(bench, "bulirsch_stoer", kExtendedReferenceTolerance));
  set.checks.push_back(dopri5_run(bench, kDopri5ReferenceTolerance));  // the former reference, for scale
  return set;
}

/// The ReferenceRun restricted to bench's checkpoint times (each must be one of set.times).
inline ReferenceRun restricted(const ReferenceSet& set, const ReferenceRun& run, const BenchScene& bench) {
  ReferenceRun part = run;
  part.states.clear();
  for (double t : bench.checkpoint_times) {
    std::size_t j = 0;
    while (j < set.times.size() && std::abs(set.times[j] - t) > 1e-9 * t) ++j;
    if (j == set.times.size()) throw std::logic_error("reference: no state at checkpoint " + std::to_string(t) + " s");
    part.states.push_back(run.states[j]);
  }
  return part;
}

/// Fills bench.reference_states and the reference's estimated error (its distance from the
/// first check at the end) and writes reference_check.csv rows: from `shared` (computed once for
/// the longest horizon) when given, else our dopri5 at 1e-13 against 1e-12, or the closed form.
inline void prepare_reference(BenchScene& bench, const ReferenceSet* shared, std::FILE* check) {
  if (bench.analytic) {
    bench.reference_name = "paper_analytic";
    bench.reference_error_position = 0.0;
    bench.reference_error_heading = 0.0;
    std::fprintf(check, "%s,paper_analytic,exact,%.9g,0,0,0,0,0,0,0\n", bench.label.c_str(), bench.scene.duration);
    return;
  }
  ReferenceRun reference;
  std::vector<ReferenceRun> checks;
  if (shared) {
    reference = restricted(*shared, shared->reference, bench);
    for (const ReferenceRun& other : shared->checks) checks.push_back(restricted(*shared, other, bench));
  } else {
    reference = dopri5_run(bench, kDopri5ReferenceTolerance);
    checks.push_back(dopri5_run(bench, kDopri5ReferenceCheckTolerance));
  }
  bench.reference_states = reference.states;
  bench.reference_name = reference.name;
  const std::size_t last = bench.checkpoint_times.size() - 1;
  const ReferenceRun& estimate = checks.front();
  bench.reference_error_position = position_distance(reference.states[last], estimate.states[last]);
  bench.reference_error_heading = std::abs(heading_difference(reference.states[last], estimate.states[last]));
  for (const ReferenceRun& other : checks) write_reference_check(check, bench, reference, other);
  std::fprintf(stderr, "  reference %s (%.1f s wall): vs %s at the end %.2e m\n", reference.name.c_str(),
               reference.wall, estimate.name.c_str(), bench.reference_error_position);
}

}  // namespace work_precision
}  // namespace birkhoff_cart
