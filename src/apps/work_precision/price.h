// work_precision --price: what one right-hand-side evaluation costs inside each method, per scene,
// side by side in one run of one binary (docs/benchmarks.md, "The price of an evaluation").
//
// Per scene of the study (jackknife_whirl over 100 s, sine_steer_torque, drive_rr_drag,
// very_stiff_hinge over their study durations):
//  - the bare right-hand side: the peers' joint rates (ż, ẏ) = (K⁻¹(∇B + ∂R/∂t + Λ), g(z, y, t)) at
//    64 states of the scene's own trajectory, cycled (the denominator of "/bare rhs"), and ż alone
//    (the Darboux chart's rate, which a collocation member's stage solve evaluates);
//  - each Birkhoffian member (birkhoff2, birkhoff_gauss4/6/8) under the adaptive control, under the
//    reversible control (where the member takes it), and at a fixed step equal to the adaptive
//    run's mean step (so that the fixed and the controlled runs walk the same h);
//  - our dopri5 and Boost.Odeint's controlled rkf78 on the same joint rates.
// A cell is one whole run from the scene's start to its end, with nothing observed on the way (the
// method's cost alone); its price is CPU time / right-hand-side evaluations [ns], the median over
// the repetitions after a warm-up; the ratios are controlled / fixed and price / bare rhs (the joint
// rates, and ż alone). birkhoff2 runs at a thousandfold looser position tolerance than the others.
//
// With --callgrind every cell runs once inside price_region(), so that
//   valgrind --tool=callgrind --toggle-collect='*price_region*' --dump-after='*work_precision::price_region*' ...
// writes one profile per cell, in the printed order (bench/price_callgrind.py divides each one's
// instructions by the cell's evaluations). The two patterns must differ: callgrind keeps one setting
// per pattern.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <functional>
#include <string>
#include <vector>

#include "birkhoff_cart/core/scene/scene.h"
#include "birkhoff_cart/core/run/simulation.h"
#include "measurement.h"
#include "odeint_peers.h"
#include "ours.h"

namespace birkhoff_cart {
namespace work_precision {

/// The settings of a --price run, from the command line.
struct PriceSettings {
  std::string scenes_dir = "config/scenes";  ///< where <scene>.yaml are
  std::string only_scene;                    ///< run this scene alone (empty: all four)
  double position_tolerance = 1e-6;          ///< the step controls' position tolerance [m]
  double peer_tolerance = 1e-8;              ///< dopri5's and rkf78's absolute = relative tolerance [-]
  int repetitions = 21;                      ///< timed runs per cell after the warm-up
  bool callgrind = false;                    ///< every cell once, inside price_region()
};

/// One scene of the price table and how long it is run [s].
struct PriceScene {
  const char* name;
  double duration;
};
constexpr PriceScene kPriceScenes[] = {
    {"jackknife_whirl", 100.0}, {"sine_steer_torque", 6.0}, {"drive_rr_drag", 8.0}, {"very_stiff_hinge", 20.0}};
const char* const kPriceMembers[] = {"birkhoff2", "birkhoff_gauss4", "birkhoff_gauss6", "birkhoff_gauss8"};

/// The region callgrind collects (and dumps after): one cell's run. Not inlined, so that its name
/// stays in the binary.
__attribute__((noinline)) inline void price_region(const std::function<void()>& run) { run(); }

/// What one cell measured.
struct PriceCell {
  std::string status = "ok";
  bool started = false;             ///< the run began (a failure then ended it part way)
  double cpu_median = NAN;          ///< [s]
  std::uint64_t evaluations = 0;    ///< right-hand-side evaluations of one run
  std::uint64_t steps = 0;          ///< accepted steps of one run
  std::uint64_t rejected = 0;       ///< rejected attempts of one run
  double nanoseconds_per_evaluation() const { return 1e9 * cpu_median / static_cast<double>(evaluations); }
};

/// Runs `run` (which sets `evaluations`) as the settings say: once in price_region() with
/// --callgrind, else a warm-up and `repetitions` timed runs (CPU time, median).
inline void time_cell(const PriceSettings& settings, PriceCell& cell, const std::function<void()>& run) {
  cell.started = true;
  if (settings.callgrind) {
    price_region(run);
    cell.cpu_median = NAN;
    return;
  }
  run();
  std::vector<double> cpus;
  for (int r = 0; r < settings.repetitions; ++r) {
    const double start = cpu_seconds();
    run();
    cpus.push_back(cpu_seconds() - start);
  }
  cell.cpu_median = median(cpus);
}

/// One of our members (or dopri5) from the scene's start to its end, nothing observed on the way.
inline PriceCell price_ours(const PriceSettings& settings, const Scene& base, const std::string& method, double step,
                            double tolerance) {
  PriceCell cell;
  try {
    Simulation sim(configured(base, method, step, tolerance));  // built outside the timed region
    const bool own_steps = sim.takes_own_steps();
    time_cell(settings, cell, [&] {
      sim.reset();
      if (own_steps) {
        sim.land_on(sim.end_time());
        sim.advance_output_to(sim.end_time());
      } else {
        while (!sim.at_end()) sim.step_on_schedule();
      }
    });
    const StepStatistics& statistics = sim.statistics();
    cell.evaluations = statistics.rhs_evaluations;
    cell.steps = own_steps ? statistics.internal_steps : statistics.steps;
    cell.rejected = statistics.rejected_steps;
  } catch (const std::exception& error) {
    cell.status = error.what();
  }
  return cell;
}

// GCC 12 reports a false -Wuninitialized in the copy constructor of odeint's explicit_error_generic_rk
// (make_controlled copies rkf78 before its buffers are sized; odeint_peers.h has the same).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
/// Boost.Odeint's controlled rkf78 on the joint rates, from the start to the end in one integration.
template <class System>
PriceCell price_rkf78(const PriceSettings& settings, const Scene& base) {
  namespace odeint = boost::numeric::odeint;
  using Joint = JointState<double>;
  PriceCell cell;
  try {
    const Simulation holder(configured(base, "rk4", 0.1, 1e-10));  // model and effects
    System system(holder.model(), holder.effects());
    const double t0 = base.initial_state.time;
    system.begin_step(t0);
    const Joint x0 = joint_start<System, double>(system, base.initial_state);
    std::uint64_t evaluations = 0;
    std::uint64_t accepted = 0;
    const JointRates<System, double> rates{&system, &evaluations};
    time_cell(settings, cell, [&] {
      evaluations = 0;
      accepted = 0;
      Joint x = x0;
      auto stepper = odeint::make_controlled(settings.peer_tolerance, settings.peer_tolerance,
                                             odeint::runge_kutta_fehlberg78<Joint>());
      integrate_through_checkpoints(
          stepper, rates, x, t0, {base.duration}, 1e-3, [&](const Joint&, double) { ++accepted; },
          [](std::size_t, const Joint&, double) {});
    });
    cell.evaluations = evaluations;
    cell.steps = accepted;
  } catch (const std::exception& error) {
    cell.status = error.what();
  }
  return cell;
}
#pragma GCC diagnostic pop

/// The bare right-hand side at 64 states of the scene's trajectory (every 100th of gauss8's steps at
/// 1/6400 of the duration), cycled, `evaluations` of them per run: the joint rates (ż, ẏ) the peers evaluate, or
/// (`birkhoffian_only`) ż = ẇ alone, the rate a collocation member's stage solve evaluates.
template <class System>
PriceCell price_bare_rates(const PriceSettings& settings, const Scene& base, std::uint64_t evaluations,
                           bool birkhoffian_only) {
  using Joint = JointState<double>;
  PriceCell cell;
  Simulation sim(configured(base, "birkhoff_gauss8", base.duration / 6400.0, 0.0));
  System system(sim.model(), sim.effects());
  system.begin_step(base.initial_state.time);
  std::vector<std::pair<Joint, double>> samples;  // (x, t [s])
  std::vector<Eigen::Matrix<double, kBirkhoffianSize, 1>> chart_points;  // w = D(z, t)
  for (int k = 0; !sim.at_end(); ++k, sim.step_on_schedule()) {
    if (k % 100 != 0) continue;
    samples.emplace_back(joint_start<System, double>(system, sim.state()), sim.state().time);
    const Eigen::Matrix<double, kBirkhoffianSize, 1> z =
        Eigen::Map<const Eigen::Matrix<double, kBirkhoffianSize, 1>>(samples.back().first.data());
    chart_points.push_back(system.to_darboux(z, sim.state().time));
  }
  std::uint64_t counted = 0;
  const JointRates<System, double> rates{&system, &counted};
  double accumulated = 0.0;
  time_cell(settings, cell, [&] {
    counted = 0;
    Joint rate{};
    for (std::uint64_t k = 0; k < evaluations; ++k) {
      const auto& sample = samples[k % samples.size()];
      if (birkhoffian_only) {
        accumulated += system.darboux_rates(chart_points[k % samples.size()], sample.second)(kSteeringAngleIndex);
        ++counted;
      } else {
        rates(sample.first, rate, sample.second);
        accumulated += rate[0] + rate[kJointSize - 1];
      }
    }
  });
  volatile double sink = accumulated;  // keeps the evaluations alive
  (void)sink;
  cell.evaluations = counted;
  return cell;
}

inline void print_price_row(const char* method, const char* control, const std::string& setting, const PriceCell& cell,
                            double fixed, double bare, double bare_birkhoffian) {
  if (cell.status != "ok") {
    std::printf("  %-16s %-10s %-12s  %s: %s\n", method, control, setting.c_str(),
                cell.started ? "failed part way" : "refused", cell.status.c_str());
    return;
  }
  const double price = cell.nanoseconds_per_evaluation();
  char ratios[64] = "";
  if (std::isfinite(price)) {
    std::snprintf(ratios, sizeof ratios, "%8.2f %8.2f %8.2f", fixed > 0.0 ? price / fixed : NAN, price / bare,
                  price / bare_birkhoffian);
  }
  std::printf("  %-16s %-10s %-12s %8llu %8llu %10llu %10.1f %s\n", method, control, setting.c_str(),
              static_cast<unsigned long long>(cell.steps), static_cast<unsigned long long>(cell.rejected),
              static_cast<unsigned long long>(cell.evaluations), price, ratios);
  std::fflush(stdout);
}

inline std::string format_setting(const char* key, double value) {
  char text[40];
  std::snprintf(text, sizeof text, "%s=%.3g", key, value);
  return text;
}

/// The price table of one scene.
template <class System>
void price_scene(const PriceSettings& settings, const PriceScene& entry, const Scene& scene) {
  std::printf("\n%s over %g s (position tolerance %g m; peers at %g)\n", entry.name, entry.duration,
              settings.position_tolerance, settings.peer_tolerance);
  std::printf("  %-16s %-10s %-12s %8s %8s %10s %10s %8s %8s %8s\n", "method", "control", "setting", "steps",
              "rejected", "rhs evals", "ns/eval", "/fixed", "/(z,y)", "/z");
  const PriceCell bare = price_bare_rates<System>(settings, scene, 200000, false);
  const double bare_price = bare.nanoseconds_per_evaluation();
  const PriceCell birkhoffian = price_bare_rates<System>(settings, scene, 200000, true);
  const double birkhoffian_price = birkhoffian.nanoseconds_per_evaluation();
  print_price_row("bare rhs", "-", "rates(z,y)", bare, NAN, bare_price, birkhoffian_price);
  print_price_row("bare rhs", "-", "rates(z)", birkhoffian, NAN, bare_price, birkhoffian_price);
  for (const char* member : kPriceMembers) {
    const std::string name = member;
    // birkhoff2 (order 2) at a thousandfold looser tolerance: at the others' it takes millions of steps.
    const double position_tolerance = settings.position_tolerance * (name == "birkhoff2" ? 1e3 : 1.0);  // [m]
    const std::string tolerance = format_setting("tol", position_tolerance);
    const PriceCell adaptive = price_ours(settings, scene, name + "_adaptive", 0.1, position_tolerance);
    const PriceCell reversible = price_ours(settings, scene, name + "_reversible", 0.1, position_tolerance);
    // The fixed step: the adaptive run's mean step (else the reversible one's), on the same grid rule.
    const PriceCell& walked = adaptive.status == "ok" ? adaptive : reversible;
    const double step = walked.status == "ok" && walked.steps > 0 ? entry.duration / static_cast<double>(walked.steps)
                                                                    : entry.duration / 1000.0;
    const PriceCell fixed = price_ours(settings, scene, name, step, 0.0);
    const double fixed_price = fixed.status == "ok" ? fixed.nanoseconds_per_evaluation() : NAN;
    print_price_row(member, "adaptive", tolerance, adaptive, fixed_price, bare_price, birkhoffian_price);
    print_price_row(member, "reversible", tolerance, reversible, fixed_price, bare_price, birkhoffian_price);
    print_price_row(member, "fixed", format_setting("h", step), fixed, fixed_price, bare_price, birkhoffian_price);
  }
  const PriceCell dopri5 = price_ours(settings, scene, "dopri5", kSampleInterval, settings.peer_tolerance);
  print_price_row("dopri5", "own", format_setting("tol", settings.peer_tolerance), dopri5, NAN, bare_price, birkhoffian_price);
  const PriceCell rkf78 = price_rkf78<System>(settings, scene);
  print_price_row("odeint_rkf78", "own", format_setting("tol", settings.peer_tolerance), rkf78, NAN, bare_price, birkhoffian_price);
}

/// --price: the table of every scene (or --scene NAME's alone). 0 done; 2 no such scene.
inline int run_price(const PriceSettings& settings) {
  bool known = settings.only_scene.empty();
  for (const PriceScene& entry : kPriceScenes) known = known || settings.only_scene == entry.name;
  if (!known) {
    std::fprintf(stderr, "work_precision --price: no scene named '%s' (jackknife_whirl, sine_steer_torque, "
                         "drive_rr_drag, very_stiff_hinge)\n", settings.only_scene.c_str());
    return 2;
  }
  std::printf("Price of a right-hand-side evaluation: CPU / evaluations, %s\n",
              settings.callgrind ? "each cell once (callgrind: instructions per cell from the profile dumps)"
                                 : ("median of " + std::to_string(settings.repetitions) +
                                    " runs after a warm-up; /fixed = controlled over the fixed step's price")
                                       .c_str());
  for (const PriceScene& entry : kPriceScenes) {
    if (!settings.only_scene.empty() && settings.only_scene != entry.name) continue;
    Scene scene = load_scene(settings.scenes_dir + "/" + entry.name + ".yaml");
    scene.reference = ReferenceSettings{};
    scene.duration = entry.duration;
    if (scene.integrator.birkhoffian_form == BirkhoffianForm::kPaper) {
      price_scene<CartPaperBirkhoffian>(settings, entry, scene);
    } else {
      price_scene<CartAutonomousBirkhoffian>(settings, entry, scene);
    }
  }
  return 0;
}

}  // namespace work_precision
}  // namespace birkhoff_cart
