// The simulator's own integrated path against the independent 8-coordinate model
// (full_coordinate_model.h, which shares no formula with CartModel): every registered integrator,
// in both Birkhoffian forms, runs a Simulation with a steering torque, a drive torque and air drag;
// the full model runs the same loads with fine-step RK4; the two are compared at every output
// instant on (x, y, θ, χ, φ1..φ4, ω1, ω2).
//
// The tolerance comes from the member's own order p (CartStepper::order()) and its step h:
//  - the error at h is below kErrorConstant · h^p + kRoundOffFloor, one constant for every member;
//  - halving the step divides the error by 2^p (observed order within kOrderSlack of p) whenever
//    the error at h/2 is above round-off (kOrderCheckFloor).
// The step grows with the order (h = 0.02, 0.04, 0.1 s for p ≤ 2, 3–4, ≥ 5) so that the errors stay
// measurable. A wrong sign of the nonholonomic force or a dropped load makes an error that does not
// shrink with h; a composition that lost its order (birkhoff4 with birkhoff2's weights) halves its
// error by 4, not 16. The cases are generated from integrator_names(), so a new member of the
// registry is covered without touching this file.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "birkhoff_cart/core/physics/cart_model.h"
#include "birkhoff_cart/core/physics/effect_library.h"
#include "birkhoff_cart/core/cart_binding/cart_stepper.h"
#include "birkhoff_cart/core/scene/scene.h"
#include "birkhoff_cart/core/run/simulation.h"
#include "full_coordinate_model.h"

namespace birkhoff_cart {
namespace {

using full_model::FullCoordinateModel;
using full_model::Vector8;

constexpr double kPi = 3.14159265358979323846;
constexpr double kDuration = 4.0;         // simulated time [s]
constexpr double kSampleInterval = 0.2;   // comparison instants [s] (a multiple of every h and h/2)
constexpr double kReferenceStep = 2.5e-4; // RK4 step of the full model [s] (its error ~1e-14)
// kErrorConstant is ~6× the largest measured error/h^p of any member (birkhoff4 in the paper form,
// see the printed "[ measured ] ..." lines); kRoundOffFloor is ~30× the error of dopri5 at 1e-12.
constexpr double kErrorConstant = 1000.0;  // [unit · s^-p] in m, rad, m/s, rad/s
constexpr double kRoundOffFloor = 1e-10;   // [unit]
constexpr double kOrderCheckFloor = 1e-8;  // errors below this are too close to round-off to halve [unit]
constexpr double kOrderSlack = 0.4;        // |observed − reported order| [-]
constexpr double kDragCoefficient = 0.4;   // k of air_drag [N·s²/m²]

/// The step for a member of order p [s].
double step_for_order(int order) { return order <= 2 ? 0.02 : order <= 4 ? 0.04 : 0.1; }

/// Loads of the run, as the scene states them and as the full model applies them.
TorqueProfile steering_profile() {
  TorqueProfile profile;
  profile.kind = TorqueProfile::Kind::kCosine;
  profile.amplitude = 7.0;   // [N·m]
  profile.frequency = 0.3;   // [Hz]
  profile.phase = -0.4;      // [rad]
  return profile;
}
TorqueProfile drive_profile() {
  TorqueProfile profile;
  profile.kind = TorqueProfile::Kind::kRamp;
  profile.initial = 10.0;  // [N·m]
  profile.final = 45.0;    // [N·m]
  profile.start_time = 0.0;
  profile.end_time = kDuration;
  return profile;
}

/// The start: B at (0.3, −0.2) m, θ = 0.4 rad, χ = 0.25 rad, wheels turned, ω = (1.2 m/s, 0.4 rad/s).
CartState start_state() {
  CartState state;
  state.x = 0.3;
  state.y = -0.2;
  state.heading = 0.4;
  state.steering_angle = 0.25;
  state.wheel_spin_angle = {0.1, -0.2, 0.3, 0.05};
  state.forward_speed = 1.2;
  state.steering_rate = 0.4;
  return state;
}

Scene driven_scene(const std::string& integrator, BirkhoffianForm form, double step) {
  Scene scene;
  scene.name = "trajectory_vs_independent_model";
  scene.initial_state = start_state();
  scene.duration = kDuration;
  scene.integrator.name = integrator;
  scene.integrator.step_size = step;
  scene.integrator.birkhoffian_form = form;
  scene.integrator.tolerance = 1e-12;  // dopri5
  EffectSpec steering;
  steering.name = "steering_torque";
  steering.profile = steering_profile();
  EffectSpec drive;
  drive.name = "drive_torque";
  drive.profile = drive_profile();
  EffectSpec drag;
  drag.name = "air_drag";
  drag.coefficients["coefficient"] = kDragCoefficient;
  scene.effects = {steering, drive, drag};
  return scene;
}

/// (x, y, θ, χ, φ1..φ4, ω1, ω2) [m, m, rad, rad, rad ×4, m/s, rad/s].
using Observables = Eigen::Matrix<double, 10, 1>;
using FullState = Eigen::Matrix<double, 16, 1>;

Observables observables_of(const CartState& s) {
  Observables o;
  o << s.x, s.y, s.heading, s.steering_angle, s.wheel_spin_angle[0], s.wheel_spin_angle[1], s.wheel_spin_angle[2],
      s.wheel_spin_angle[3], s.forward_speed, s.steering_rate;
  return o;
}

Observables observables_of_full(const FullState& y) {
  const Vector8 q = y.head<8>(), qd = y.tail<8>();
  Observables o;
  o << q, FullCoordinateModel::front_axle_speed(q, qd), qd(full_model::kSteering);
  return o;
}

/// The full model's path sampled every kSampleInterval: the same torques applied in the eight
/// coordinates (τ on χ, T/2 on φ1 and φ2) and the drag −k|v_A| v_A at A through A's position
/// Jacobian. Computed once.
const std::vector<Observables>& independent_path() {
  static const std::vector<Observables> path = [] {
    const CartParameters parameters;
    const FullCoordinateModel full(parameters);
    const TorqueProfile steering = steering_profile(), drive = drive_profile();
    const auto rate = [&](double t, const FullState& y) {
      const Vector8 q = y.head<8>(), qd = y.tail<8>();
      full_model::AppliedLoads loads;
      loads.steering_torque = steering.at(t);
      loads.drive_torque = drive.at(t);
      Vector8 force = FullCoordinateModel::applied_force(loads);
      const Eigen::Matrix<double, 2, 8> jacobian = full_model::position_jacobian<double>(full.bodies()[0], q);
      const Eigen::Vector2d velocity_a = jacobian * qd;  // v_A [m/s]
      force += jacobian.transpose() * (-kDragCoefficient * velocity_a.norm() * velocity_a);
      FullState derivative;
      derivative << qd, full.acceleration(q, qd, force);
      return derivative;
    };
    const CartState s0 = start_state();
    Vector8 q0;
    q0 << s0.x, s0.y, s0.heading, s0.steering_angle, s0.wheel_spin_angle[0], s0.wheel_spin_angle[1],
        s0.wheel_spin_angle[2], s0.wheel_spin_angle[3];
    FullState y;
    y << q0, full.admissible_velocity(q0, s0.forward_speed, s0.steering_rate);
    const int steps_per_sample = static_cast<int>(std::lround(kSampleInterval / kReferenceStep));
    const int samples = static_cast<int>(std::lround(kDuration / kSampleInterval));
    std::vector<Observables> sampled;
    for (int k = 0; k < samples; ++k) {
      for (int j = 0; j < steps_per_sample; ++j) {
        const double t = (k * steps_per_sample + j) * kReferenceStep;
        y = full_model::runge_kutta4_step(rate, t, y, kReferenceStep);
      }
      sampled.push_back(observables_of_full(y));
    }
    return sampled;
  }();
  return path;
}

struct Member {
  std::string integrator;
  BirkhoffianForm form;
};

std::vector<Member> all_members() {
  std::vector<Member> members;
  for (const std::string& name : integrator_names()) {
    for (BirkhoffianForm form : {BirkhoffianForm::kAutonomous, BirkhoffianForm::kPaper}) members.push_back({name, form});
  }
  return members;
}

std::string member_label(const testing::TestParamInfo<Member>& info) {
  return info.param.integrator + "_" + to_string(info.param.form);
}

/// The largest difference between the simulator's path and the independent model's.
struct PathError {
  double worst = 0.0;             ///< [m, rad, m/s, rad/s]
  int component = -1;             ///< index in Observables
  double time = 0.0;              ///< [s]
  double max_abs_steering = 0.0;  ///< [rad]
  double final_forward_speed = 0.0;  ///< [m/s]
};

PathError path_error(const Member& member, double step) {
  Simulation simulation(driven_scene(member.integrator, member.form, step));
  const std::vector<Observables>& reference = independent_path();
  PathError result;
  for (std::size_t k = 0; k < reference.size(); ++k) {
    const double time = (static_cast<double>(k) + 1.0) * kSampleInterval;
    simulation.advance_to(time);
    EXPECT_NEAR(simulation.state().time, time, 1e-12);
    const Observables difference = (observables_of(simulation.state()) - reference[k]).cwiseAbs();
    int component = 0;
    const double largest = difference.maxCoeff(&component);
    if (largest > result.worst) {
      result.worst = largest;
      result.component = component;
      result.time = time;
    }
    result.max_abs_steering = std::max(result.max_abs_steering, std::abs(simulation.state().steering_angle));
  }
  result.final_forward_speed = simulation.state().forward_speed;
  return result;
}

class TrajectoryAgainstIndependentModel : public testing::TestWithParam<Member> {};

TEST_P(TrajectoryAgainstIndependentModel, AgreesWithinTheMembersOrderBound) {
  const Member& member = GetParam();
  IntegratorSettings settings;
  settings.name = member.integrator;
  settings.birkhoffian_form = member.form;
  const CartModel probe{CartParameters{}};
  const EffectSet no_loads;
  const int order = make_cart_stepper(settings, probe, no_loads)->order();
  const double h = step_for_order(order);
  const double bound = kErrorConstant * std::pow(h, order) + kRoundOffFloor;

  const PathError at_h = path_error(member, h);
  const PathError at_half = path_error(member, h / 2);
  const double observed_order = std::log2(at_h.worst / at_half.worst);
  std::cout << "[ measured ] " << member.integrator << " (" << to_string(member.form) << ", order " << order << ", h = " << h
            << " s): max |simulator − independent| = " << at_h.worst << " (component " << at_h.component
            << " at t = " << at_h.time << " s), error/h^p = " << at_h.worst / std::pow(h, order) << ", bound " << bound
            << "; at h/2: " << at_half.worst << ", observed order " << observed_order << "\n";
  EXPECT_LT(at_h.worst, bound) << member.integrator << " (" << to_string(member.form) << ")";
  EXPECT_LT(at_half.worst, kErrorConstant * std::pow(h / 2, order) + kRoundOffFloor);
  if (at_half.worst > kOrderCheckFloor) {
    EXPECT_NEAR(observed_order, order, kOrderSlack) << member.integrator << " (" << to_string(member.form) << ")";
  }
  // The run really exercises the loads: the drive sped the cart up and the steering swung.
  EXPECT_GT(at_h.final_forward_speed, 2.0 * start_state().forward_speed);
  EXPECT_GT(at_h.max_abs_steering, 0.5);
  EXPECT_LT(at_h.max_abs_steering, kPi / 2);
}

INSTANTIATE_TEST_SUITE_P(EveryMemberBothForms, TrajectoryAgainstIndependentModel, testing::ValuesIn(all_members()),
                         member_label);

}  // namespace
}  // namespace birkhoff_cart
