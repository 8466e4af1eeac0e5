// work_precision: Boost.Odeint's steppers on the same right-hand side as ours (the scene's
// Birkhoffian form: ż = birkhoffian_rates, ẏ = passive_coordinate_rates), in double and — for the
// reference — in long double.
#pragma once

#include <algorithm>
#include <array>
// GCC 12 reports a false -Wmaybe-uninitialized in the copy constructor of odeint's
// explicit_error_generic_rk (rkf78's buffers are sized by the initially_resizer before any use).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <boost/numeric/odeint.hpp>
#pragma GCC diagnostic pop
#include <cstdint>
#include <exception>
#include <stdexcept>
#include <string>

#include "bench_scene.h"
#include "birkhoff_cart/core/physics/cart_birkhoffian.h"
#include "birkhoff_cart/core/integrators/odeint_step_adjuster.h"
#include "birkhoff_cart/core/run/simulation.h"
#include "measurement.h"
#include "ours.h"

namespace birkhoff_cart {
namespace work_precision {

constexpr int kJointSize = kBirkhoffianSize + kPassiveSize;
template <class S>
using JointState = std::array<S, kJointSize>;  ///< (z, y)

/// d(z, y)/dt of the cart's Birkhoffian system with scalar S, counting its evaluations.
template <class System, class S>
struct JointRates {
  const System* system;
  std::uint64_t* evaluations;
  void operator()(const JointState<S>& x, JointState<S>& rate, S t) const {
    Eigen::Matrix<S, kBirkhoffianSize, 1> z;
    Eigen::Matrix<S, kPassiveSize, 1> y;
    for (int i = 0; i < kBirkhoffianSize; ++i) z(i) = x[i];
    for (int i = 0; i < kPassiveSize; ++i) y(i) = x[kBirkhoffianSize + i];
    const auto z_rate = birkhoffian_rates(*system, z, t);            // ż = K⁻¹(∇B + ∂R/∂t + Λ)
    const auto y_rate = passive_coordinate_rates(*system, z, y, t);  // ẏ = g(z, y, t)
    for (int i = 0; i < kBirkhoffianSize; ++i) rate[i] = z_rate(i);
    for (int i = 0; i < kPassiveSize; ++i) rate[kBirkhoffianSize + i] = y_rate(i);
    ++*evaluations;
  }
};

template <class System, class S>
JointState<S> joint_start(const System& system, const CartState& initial) {
  const CartBirkhoffianPoint start = system.to_birkhoffian(initial);
  JointState<S> x;
  for (int i = 0; i < kBirkhoffianSize; ++i) x[i] = start.z(i);
  for (int i = 0; i < kPassiveSize; ++i) x[kBirkhoffianSize + i] = start.y(i);
  return x;
}

template <class System, class S>
CartState joint_to_cart_state(const System& system, const JointState<S>& x, double t) {
  Eigen::Matrix<double, kBirkhoffianSize, 1> z;
  Eigen::Matrix<double, kPassiveSize, 1> y;
  for (int i = 0; i < kBirkhoffianSize; ++i) z(i) = static_cast<double>(x[i]);
  for (int i = 0; i < kPassiveSize; ++i) y(i) = static_cast<double>(x[kBirkhoffianSize + i]);
  return system.to_cart_state(z, y, t);
}

/// Residuals of a joint state (z, y) like Simulation::diagnostics().
template <class System>
void sample_joint(const System& system, const JointState<double>& x, double energy0, double p20, RunErrors& errors) {
  Eigen::Matrix<double, kBirkhoffianSize, 1> z;
  for (int i = 0; i < kBirkhoffianSize; ++i) z(i) = x[i];
  const double energy = system.hamiltonian(z);  // T* = ½ pᵀM⁻¹p [J]
  const double work = x[kBirkhoffianSize + kAppliedWorkIndex];
  const double impulse = x[kBirkhoffianSize + kSteeringImpulseIndex];
  errors.max_energy_residual = std::max(errors.max_energy_residual, std::abs(energy - energy0 - work));
  errors.max_p2_residual = std::max(errors.max_p2_residual, std::abs(z(kSteeringMomentumIndex) - p20 - impulse));
}

/// One adaptive integration from t0 through the checkpoint times t0 + τⱼ with one controlled
/// stepper (its step-size memory and, for dopri5, its FSAL rate carried throughout: no restarts).
/// A step is shortened only to land on a checkpoint, after which the step size in use before
/// that landing is resumed. `observe(x, t)` after every accepted step; `at_checkpoint(j, x, t)`.
template <class Stepper, class Rates, class State, class Time, class Observe, class AtCheckpoint>
void integrate_through_checkpoints(Stepper& stepper, const Rates& rates, State& x, Time t0,
                                   const std::vector<double>& checkpoint_times, Time first_step, Observe observe,
                                   AtCheckpoint at_checkpoint) {
  namespace odeint = boost::numeric::odeint;
  constexpr int kMaxRejectionsInARow = 500;
  Time t = t0, dt = first_step;
  for (std::size_t j = 0; j < checkpoint_times.size(); ++j) {
    const Time target = t0 + Time(checkpoint_times[j]);
    int rejections = 0;
    while (target - t > Time(1e-12) * (Time(1) + std::abs(target))) {
      const bool landing = t + dt >= target;
      const Time kept = dt;
      Time trial = landing ? target - t : dt;
      if (stepper.try_step(rates, x, t, trial) == odeint::success) {  // x, t advanced; trial ← next step
        rejections = 0;
        dt = landing ? std::max(trial, kept) : trial;
        observe(x, t);
      } else {
        dt = trial;  // the smaller step it proposes
        if (++rejections > kMaxRejectionsInARow) throw std::runtime_error("adaptive step rejected 500 times in a row");
      }
    }
    t = target;
    at_checkpoint(j, x, t);
  }
}

/// Odeint peers: odeint_rk4 (fixed h), odeint_dopri5, odeint_rkf78, odeint_bulirsch_stoer
/// (controlled, absolute = relative tolerance) and odeint_bulirsch_stoer_dense_out.
template <class System>
RunRecord measure_odeint_typed(const BenchScene& bench, const std::string& method, double nominal_step,
                               double tolerance, int repetitions) {
  namespace odeint = boost::numeric::odeint;
  using Joint = JointState<double>;
  RunRecord record;
  record.scene = bench.label;
  record.method = method;
  record.kind = "odeint";
  record.duration = bench.scene.duration;
  const bool adaptive = method != "odeint_rk4";
  const std::uint64_t steps = adaptive ? 0 : step_count(bench.scene.duration, nominal_step);
  const double h = adaptive ? NAN : bench.scene.duration / static_cast<double>(steps);
  if (adaptive) record.tolerance = tolerance;
  else record.step_size = h;
  const Simulation holder(configured(bench.scene, "rk4", 0.1, 1e-10));  // model and effects
  System system(holder.model(), holder.effects());
  const double t0 = bench.scene.initial_state.time;
  system.begin_step(t0);  // rep (a): structure epoch at the start (paper_special only: short)
  const Joint x0 = joint_start<System, double>(system, bench.scene.initial_state);
  Eigen::Matrix<double, kBirkhoffianSize, 1> z0;
  for (int i = 0; i < kBirkhoffianSize; ++i) z0(i) = x0[i];
  const double energy0 = system.hamiltonian(z0);
  const double p20 = z0(kSteeringMomentumIndex);
  std::uint64_t evaluations = 0, accepted = 0;
  const JointRates<System, double> rates{&system, &evaluations};
  Joint x_end{};
  try {
    RunErrors errors = timed(repetitions, record, [&] {
      evaluations = 0;
      accepted = 0;
      RunErrors e;
      e.energy_scale = energy0;
      Joint x = x0;
      const auto observe = [&](const Joint& state, double) {
        ++accepted;
        sample_joint(system, state, energy0, p20, e);
      };
      const auto at_checkpoint = [&](std::size_t j, const Joint& state, double t) {
        e.checkpoints.push_back(checkpoint_error(bench, j, joint_to_cart_state(system, state, t), e.max_energy_residual));
      };
      if (method == "odeint_dopri5") {
        auto stepper = deterministic_controlled(tolerance, tolerance, odeint::runge_kutta_dopri5<Joint>());
        integrate_through_checkpoints(stepper, rates, x, t0, bench.checkpoint_times, 1e-3, observe, at_checkpoint);
      } else if (method == "odeint_rkf78") {
        auto stepper = deterministic_controlled(tolerance, tolerance, odeint::runge_kutta_fehlberg78<Joint>());
        integrate_through_checkpoints(stepper, rates, x, t0, bench.checkpoint_times, 1e-3, observe, at_checkpoint);
      } else if (method == "odeint_bulirsch_stoer") {
        odeint::bulirsch_stoer<Joint> stepper(tolerance, tolerance);
        integrate_through_checkpoints(stepper, rates, x, t0, bench.checkpoint_times, 1e-3, observe, at_checkpoint);
      } else if (method == "odeint_bulirsch_stoer_dense_out") {
        // Dense output: the extrapolation steps as large as the tolerance allows and the state is
        // interpolated at the observation times (every kSampleInterval and every checkpoint).
        odeint::bulirsch_stoer_dense_out<Joint> stepper(tolerance, tolerance);
        std::vector<double> times{t0};
        const std::uint64_t samples = step_count(bench.scene.duration, kSampleInterval);
        for (std::uint64_t k = 1; k <= samples; ++k) {
          times.push_back(t0 + bench.scene.duration * static_cast<double>(k) / static_cast<double>(samples));
        }
        for (double c : bench.checkpoint_times) times.push_back(t0 + c);
        std::sort(times.begin(), times.end());
        times.erase(std::unique(times.begin(), times.end(),
                                [](double a, double b) { return std::abs(a - b) <= 1e-9 * (1.0 + std::abs(b)); }),
                    times.end());
        std::size_t next = 0;
        odeint::integrate_times(stepper, rates, x, times.begin(), times.end(), 1e-3, [&](const Joint& state, double t) {
          ++accepted;  // observation times, not the extrapolation's own steps
          sample_joint(system, state, energy0, p20, e);
          if (next < bench.checkpoint_times.size() &&
              std::abs(t - (t0 + bench.checkpoint_times[next])) <= 1e-9 * (1.0 + std::abs(t))) {
            at_checkpoint(next++, state, t);
          }
          x_end = state;
        });
        return e;
      } else if (method == "odeint_rk4") {
        const std::vector<std::uint64_t> checkpoints = checkpoint_steps(bench, steps);
        const std::uint64_t sample_every = std::max<std::uint64_t>(1, std::llround(kSampleInterval / h));
        odeint::runge_kutta4<Joint> stepper;
        std::size_t next = 0;
        for (std::uint64_t k = 1; k <= steps; ++k) {
          stepper.do_step(rates, x, t0 + static_cast<double>(k - 1) * h, h);  // x ← RK4 step
          while (next < checkpoints.size() && checkpoints[next] < k) ++next;
          const bool at = next < checkpoints.size() && checkpoints[next] == k;
          if (k % sample_every == 0 || at) sample_joint(system, x, energy0, p20, e);
          if (at) at_checkpoint(next++, x, t0 + static_cast<double>(k) * h);
        }
        accepted = steps;
      } else {
        throw std::invalid_argument("unknown odeint method '" + method + "'");
      }
      x_end = x;
      return e;
    });
    record.steps = accepted;
    record.rhs_evaluations = evaluations;
    record.errors = errors;
    fill_final_errors(bench, joint_to_cart_state(system, x_end, t0 + bench.scene.duration), record.errors);
  } catch (const std::exception& error) {
    record.status = std::string("failed: ") + error.what();
  }
  return record;
}

inline RunRecord measure_odeint(const BenchScene& bench, const std::string& method, double step, double tolerance,
                                int repetitions) {
  if (bench.scene.integrator.birkhoffian_form == BirkhoffianForm::kPaper) {
    return measure_odeint_typed<CartPaperBirkhoffian>(bench, method, step, tolerance, repetitions);
  }
  return measure_odeint_typed<CartAutonomousBirkhoffian>(bench, method, step, tolerance, repetitions);
}

}  // namespace work_precision
}  // namespace birkhoff_cart
