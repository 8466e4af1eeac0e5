// Effects (docs/derivation.md §4, eqs. (4.1)–(4.6)): forces against their formulas and against
// the power they must deliver, analytic Jacobians against central differences, torque profiles,
// command inputs, and proof that only enabled effects exist and are evaluated.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <cstring>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "birkhoff_cart/core/integrators/autodiff.h"
#include "birkhoff_cart/core/physics/cart_model.h"
#include "birkhoff_cart/core/physics/effect_library.h"
#include "birkhoff_cart/core/physics/effects.h"
#include "birkhoff_cart/core/integrators/deterministic_math.h"
#include "birkhoff_cart/core/physics/effects/air_drag.h"
#include "birkhoff_cart/core/physics/effects/drive_torque.h"
#include "birkhoff_cart/core/physics/effects/rolling_resistance.h"
#include "birkhoff_cart/core/physics/effects/steering_damping.h"
#include "birkhoff_cart/core/physics/effects/steering_stiffness.h"
#include "birkhoff_cart/core/physics/effects/steering_torque.h"
#include "birkhoff_cart/core/physics/effects/torque_source.h"
#include "birkhoff_cart/core/scene/scene.h"
#include "all_effects.h"

namespace birkhoff_cart {
namespace {

constexpr double kForceTolerance = 1e-12;            // relative, of a closed-form force [-]
constexpr double kPowerTolerance = 1e-10;            // absolute, on ω·Q vs wheel power [W]
constexpr double kDifferenceStep = 1e-6;             // central-difference step in χ [rad], ω [m/s, rad/s]
constexpr double kJacobianTolerance = 1e-6;          // relative to the entry scale [-]
constexpr double kProfileTolerance = 1e-14;          // [N·m]

EffectInput make_input(double time, double steering_angle, double forward_speed, double steering_rate) {
  EffectInput input;
  input.time = time;
  input.steering_angle = steering_angle;
  input.forward_speed = forward_speed;
  input.steering_rate = steering_rate;
  return input;
}

/// States that exercise signs, large steering, reversing and speeds inside the tanh band.
std::vector<EffectInput> sample_states() {
  return {make_input(0.0, 0.0, 3.0, 0.0),    make_input(0.7, 0.3, 2.5, -0.4),  make_input(1.3, -1.1, -1.8, 0.9),
          make_input(2.9, 2.4, 0.02, -0.03), make_input(5.0, -0.05, -0.01, 1.7), make_input(8.0, 1.2, 6.0, 2.2)};
}

EffectSpec coefficient_spec(const std::string& name, std::map<std::string, double> coefficients) {
  EffectSpec spec;
  spec.name = name;
  spec.coefficients = std::move(coefficients);
  return spec;
}

EffectSpec torque_spec(const std::string& name, const TorqueProfile& profile) {
  EffectSpec spec;
  spec.name = name;
  spec.profile = profile;
  return spec;
}

TorqueProfile cosine(double amplitude, double frequency, double phase) {
  TorqueProfile profile;
  profile.kind = TorqueProfile::Kind::kCosine;
  profile.amplitude = amplitude;
  profile.frequency = frequency;
  profile.phase = phase;
  return profile;
}

TorqueProfile constant(double value) {
  TorqueProfile profile;
  profile.kind = TorqueProfile::Kind::kConstant;
  profile.value = value;
  return profile;
}

/// One spec of each of the six effects, with non-trivial coefficients.
void expect_force_near(const Eigen::Vector2d& actual, const Eigen::Vector2d& expected, const std::string& where) {
  for (int row = 0; row < 2; ++row) {
    EXPECT_NEAR(actual(row), expected(row), kForceTolerance * (1.0 + std::abs(expected(row)))) << where << " row " << row;
  }
}

// ----------------------------------------------------------------------------------------------
// Forces against their formulas.

TEST(Effects, SteeringTorqueIsTheProfileOnTheSecondQuasiVelocity) {
  const SteeringTorque effect{TorqueSource(cosine(3.0, 0.5, 0.2))};
  for (const EffectInput& input : sample_states()) {
    GeneralizedForce total;
    effect.add_to(input, total);
    // (4.1): Q = (0, τ(t))
    expect_force_near(total.force, Eigen::Vector2d(0.0, 3.0 * std::cos(2 * M_PI * 0.5 * input.time + 0.2)), "steering");
    EXPECT_TRUE(total.jacobian.isZero());
  }
}

TEST(Effects, DriveTorqueFormula) {
  const CartParameters cart;
  const DriveTorque effect(TorqueSource(constant(60.0)), cart.rear_wheel_radius);
  for (const EffectInput& input : sample_states()) {
    GeneralizedForce total;
    effect.add_to(input, total);
    // (4.2): Q = (T cos χ / r1, 0)
    expect_force_near(total.force, Eigen::Vector2d(60.0 * std::cos(input.steering_angle) / 0.14, 0.0), "drive");
  }
}

TEST(Effects, AirDragFormula) {
  const AirDrag effect(0.3);
  for (const EffectInput& input : sample_states()) {
    GeneralizedForce total;
    effect.add_to(input, total);
    const double c = std::cos(input.steering_angle);
    // (4.4): Q1 = −k |ω1 c| ω1 c²
    expect_force_near(total.force,
                      Eigen::Vector2d(-0.3 * std::abs(input.forward_speed * c) * input.forward_speed * c * c, 0.0), "drag");
  }
}

TEST(Effects, SteeringDampingAndStiffnessFormulas) {
  const SteeringDamping damping(5.0);
  const SteeringStiffness stiffness(2000.0);
  for (const EffectInput& input : sample_states()) {
    GeneralizedForce damped;
    damping.add_to(input, damped);
    expect_force_near(damped.force, Eigen::Vector2d(0.0, -5.0 * input.steering_rate), "damping");  // (4.5)
    GeneralizedForce sprung;
    stiffness.add_to(input, sprung);
    expect_force_near(sprung.force, Eigen::Vector2d(0.0, -2000.0 * input.steering_angle), "stiffness");  // (4.6)
  }
}

TEST(Effects, RollingResistanceStraightAheadIsTheTotalWeightTimesTheCoefficient) {
  // χ = 0, ω2 = 0: every rim rolls at ω1, so Q1 = −c_rr (total weight) tanh(ω1/v_eps), Q2 = 0
  // (the two front wheels' ±c lever arms cancel).
  const CartModel model{CartParameters{}};
  const RollingResistance effect(model, 0.015, 0.05);
  const CartParameters& p = model.parameters();
  const double weight = (p.rear_body_mass + 2 * p.rear_wheel_mass + p.front_axle_mass + 2 * p.front_wheel_mass) * p.gravity;
  for (double speed : {3.0, -2.0, 0.01}) {
    GeneralizedForce total;
    effect.add_to(make_input(0.0, 0.0, speed, 0.0), total);
    expect_force_near(total.force, Eigen::Vector2d(-0.015 * weight * std::tanh(speed / 0.05), 0.0), "straight");
  }
}

TEST(Effects, RollingResistanceNormalLoadsSplitEachBodyOverItsAxle) {
  const CartModel model{CartParameters{}};
  const RollingResistance effect(model, 0.015, 0.05);
  EXPECT_DOUBLE_EQ(effect.normal_load(0), (70.0 + 3.0) * 9.81);
  EXPECT_DOUBLE_EQ(effect.normal_load(1), (70.0 + 3.0) * 9.81);
  EXPECT_DOUBLE_EQ(effect.normal_load(2), (6.0 + 2.2) * 9.81);
  EXPECT_DOUBLE_EQ(effect.normal_load(3), (6.0 + 2.2) * 9.81);
}

// The power a generalized force delivers, ω·Q, must equal the physical power of the loads, computed
// independently from the wheel spin rates of the kinematic reconstruction (eq. (2.4)).
TEST(Effects, WheelTorquesDeliverThePowerOfTheirGeneralizedForce) {
  const CartModel model{CartParameters{}};
  const RollingResistance rolling(model, 0.015, 0.05);
  const DriveTorque drive(TorqueSource(constant(60.0)), model.parameters().rear_wheel_radius);
  for (const EffectInput& input : sample_states()) {
    const Vector2<double> omega(input.forward_speed, input.steering_rate);
    const CoordinateRates<double> rates = model.coordinate_rates(0.0, input.steering_angle, omega);
    double rolling_power = 0.0;  // Σ τ_i φ̇_i [W]
    for (int wheel = 0; wheel < 4; ++wheel) {
      const double radius = model.wheel_radius(wheel);
      const double torque = -0.015 * rolling.normal_load(wheel) * radius *
                            std::tanh(radius * rates.wheel_spin_rate[wheel] / 0.05);  // τ_i [N·m]
      rolling_power += torque * rates.wheel_spin_rate[wheel];
    }
    GeneralizedForce rolling_force;
    rolling.add_to(input, rolling_force);
    EXPECT_NEAR(omega.dot(rolling_force.force), rolling_power, kPowerTolerance);
    EXPECT_LE(omega.dot(rolling_force.force), 0.0);  // dissipative

    // Drive: T/2 on each rear wheel.
    const double drive_power = 30.0 * (rates.wheel_spin_rate[0] + rates.wheel_spin_rate[1]);
    GeneralizedForce drive_force;
    drive.add_to(input, drive_force);
    EXPECT_NEAR(omega.dot(drive_force.force), drive_power, kPowerTolerance);
  }
}

TEST(Effects, AirDragPowerIsTheDragForceTimesTheSpeedOfA) {
  const CartModel model{CartParameters{}};
  const AirDrag drag(0.3);
  for (const EffectInput& input : sample_states()) {
    const Vector2<double> omega(input.forward_speed, input.steering_rate);
    // v_A from A = B − l e with the reconstruction's ẋ, ẏ, θ̇, projected on the heading e (θ = 0.4).
    const double heading = 0.4;
    const CoordinateRates<double> rates = model.coordinate_rates(heading, input.steering_angle, omega);
    const double l = model.parameters().wheelbase;
    const double ax = rates.x_rate + l * std::sin(heading) * rates.heading_rate;
    const double ay = rates.y_rate - l * std::cos(heading) * rates.heading_rate;
    const double speed_a = ax * std::cos(heading) + ay * std::sin(heading);
    GeneralizedForce force;
    drag.add_to(input, force);
    EXPECT_NEAR(omega.dot(force.force), -0.3 * std::abs(speed_a) * speed_a * speed_a, kPowerTolerance);
  }
}

// ----------------------------------------------------------------------------------------------
// Jacobians.

void expect_jacobian_matches_differences(const EffectSet& effects, const EffectInput& input, const std::string& where) {
  const GeneralizedForce analytic = effects.evaluate(input);
  for (int column = 0; column < 3; ++column) {
    EffectInput plus = input;
    EffectInput minus = input;
    double* plus_value = column == 0 ? &plus.steering_angle : column == 1 ? &plus.forward_speed : &plus.steering_rate;
    double* minus_value = column == 0 ? &minus.steering_angle : column == 1 ? &minus.forward_speed : &minus.steering_rate;
    *plus_value += kDifferenceStep;
    *minus_value -= kDifferenceStep;
    const Eigen::Vector2d difference =
        (effects.evaluate(plus).force - effects.evaluate(minus).force) / (2.0 * kDifferenceStep);
    for (int row = 0; row < 2; ++row) {
      const double scale = 1.0 + std::abs(analytic.jacobian(row, column)) + std::abs(analytic.force(row));
      EXPECT_NEAR(analytic.jacobian(row, column), difference(row), kJacobianTolerance * scale)
          << where << ": dQ" << row + 1 << "/d" << (column == 0 ? "chi" : column == 1 ? "w1" : "w2");
    }
  }
}

TEST(Effects, EachAnalyticJacobianMatchesCentralDifferences) {
  const CartModel model{CartParameters{}};
  for (const EffectSpec& spec : birkhoff_cart_test::all_effect_specs()) {
    const EffectSet single = build_effects({spec}, model);
    ASSERT_EQ(single.size(), 1u);
    // Rolling resistance: a wider band so the tanh is resolved by the difference step.
    for (const EffectInput& input : sample_states()) expect_jacobian_matches_differences(single, input, spec.name);
  }
  const EffectSet all = build_effects(birkhoff_cart_test::all_effect_specs(), model);
  for (const EffectInput& input : sample_states()) expect_jacobian_matches_differences(all, input, "all effects");
}

TEST(Effects, AutomaticDifferentiationLiftCarriesTheAnalyticJacobian) {
  const CartModel model{CartParameters{}};
  const EffectSet effects = build_effects(birkhoff_cart_test::all_effect_specs(), model);
  using Scalar = Jet<3>;
  for (const EffectInput& input : sample_states()) {
    const Scalar chi(input.steering_angle, 3, 0);
    const Vector2<Scalar> omega(Scalar(input.forward_speed, 3, 1), Scalar(input.steering_rate, 3, 2));
    const Vector2<Scalar> lifted = effects.generalized_force<Scalar>(input.time, chi, omega);
    const GeneralizedForce plain = effects.evaluate(input);
    for (int row = 0; row < 2; ++row) {
      EXPECT_DOUBLE_EQ(lifted(row).value(), plain.force(row));
      for (int column = 0; column < 3; ++column) {
        EXPECT_DOUBLE_EQ(lifted(row).derivatives()(column), plain.jacobian(row, column));
      }
    }
  }
}

// ----------------------------------------------------------------------------------------------
// Torque profiles and the command source.

TEST(TorqueProfiles, ValuesAtChosenTimes) {
  const TorqueProfile wave = cosine(3.0, 0.5, -M_PI / 2);  // = 3 sin(π t)
  EXPECT_NEAR(wave.at(0.5), 3.0, kProfileTolerance);
  EXPECT_NEAR(wave.at(1.5), -3.0, kProfileTolerance);
  EXPECT_NEAR(wave.at(1.0), 0.0, kProfileTolerance);

  TorqueProfile step;
  step.kind = TorqueProfile::Kind::kStep;
  step.initial = 2.0;
  step.final = -1.0;
  step.step_time = 1.0;
  EXPECT_EQ(step.at(0.999), 2.0);
  EXPECT_EQ(step.at(1.0), -1.0);
  EXPECT_EQ(step.at(7.0), -1.0);

  TorqueProfile ramp;
  ramp.kind = TorqueProfile::Kind::kRamp;
  ramp.initial = 12.0;
  ramp.final = 4.0;
  ramp.start_time = 2.0;
  ramp.end_time = 6.0;
  EXPECT_EQ(ramp.at(0.0), 12.0);
  EXPECT_NEAR(ramp.at(3.0), 10.0, kProfileTolerance);
  EXPECT_NEAR(ramp.at(5.0), 6.0, kProfileTolerance);
  EXPECT_EQ(ramp.at(9.0), 4.0);

  TorqueProfile switch_off;
  switch_off.kind = TorqueProfile::Kind::kSmoothSwitchOff;
  switch_off.initial = 60.0;
  switch_off.switch_off_time = 4.0;
  switch_off.width = 0.3;
  EXPECT_NEAR(switch_off.at(4.0), 30.0, kProfileTolerance);  // half-way at t_off
  EXPECT_NEAR(switch_off.at(0.0), 60.0 * 0.5 * (1.0 - std::tanh(-4.0 / 0.3)), kProfileTolerance);
  EXPECT_GT(switch_off.at(0.0), 59.999999);
  EXPECT_LT(switch_off.at(8.0), 1e-9);

  EXPECT_EQ(constant(0.4).at(123.0), 0.4);
}

TEST(TorqueProfiles, CommandSourceReadsTheSharedCommandInput) {
  const CartModel model{CartParameters{}};
  TorqueProfile command;
  command.kind = TorqueProfile::Kind::kCommand;
  command.value = 0.5;  // initial command [N·m]
  const EffectSet effects =
      build_effects({torque_spec("steering_torque", command), torque_spec("drive_torque", command)}, model);
  ASSERT_NE(effects.steering_command(), nullptr);
  ASSERT_NE(effects.drive_command(), nullptr);
  EXPECT_NE(effects.steering_command(), effects.drive_command());
  const EffectInput straight = make_input(1.0, 0.0, 1.0, 0.0);
  EXPECT_DOUBLE_EQ(effects.evaluate(straight).force(1), 0.5);
  EXPECT_DOUBLE_EQ(effects.evaluate(straight).force(0), 0.5 / 0.14);

  effects.steering_command()->value = -2.0;
  effects.drive_command()->value = 7.0;
  EXPECT_DOUBLE_EQ(effects.evaluate(straight).force(1), -2.0);
  EXPECT_DOUBLE_EQ(effects.evaluate(straight).force(0), 7.0 / 0.14);
  // Zero-order hold: time does not change a command.
  EXPECT_DOUBLE_EQ(effects.evaluate(make_input(50.0, 0.0, 1.0, 0.0)).force(1), -2.0);
}

TEST(TorqueProfiles, ProfileEffectsHaveNoCommandInput) {
  const CartModel model{CartParameters{}};
  const EffectSet effects = build_effects(birkhoff_cart_test::all_effect_specs(), model);
  EXPECT_EQ(effects.steering_command(), nullptr);
  EXPECT_EQ(effects.drive_command(), nullptr);
}

// ----------------------------------------------------------------------------------------------
// Only enabled effects exist and are evaluated.

/// Counts its evaluations; adds nothing.
class CountingEffect : public Effect {
 public:
  CountingEffect(std::string name, int* calls) : name_(std::move(name)), calls_(calls) {}
  const std::string& name() const override { return name_; }
  void add_to(const EffectInput&, GeneralizedForce&) const override { ++*calls_; }

 private:
  std::string name_;
  int* calls_;
};

TEST(EffectSet, HoldsExactlyTheEnabledEffectsInOrder) {
  const CartModel model{CartParameters{}};
  std::vector<EffectSpec> specs = birkhoff_cart_test::all_effect_specs();
  specs.erase(specs.begin() + 3);  // no air_drag
  specs.erase(specs.begin());      // no steering_torque
  const EffectSet effects = build_effects(specs, model);
  ASSERT_EQ(effects.size(), 4u);
  EXPECT_EQ(effects.effects()[0]->name(), "drive_torque");
  EXPECT_EQ(effects.effects()[1]->name(), "rolling_resistance");
  EXPECT_EQ(effects.effects()[2]->name(), "steering_damping");
  EXPECT_EQ(effects.effects()[3]->name(), "steering_stiffness");
  EXPECT_TRUE(build_effects({}, model).empty());
}

TEST(EffectSet, EvaluateCallsOnlyTheEffectsItHolds) {
  int enabled_calls = 0;
  int disabled_calls = 0;
  EffectSet effects;
  effects.add(std::make_unique<CountingEffect>("enabled", &enabled_calls));
  const CountingEffect left_out("disabled", &disabled_calls);  // built but never added
  for (int evaluation = 0; evaluation < 5; ++evaluation) effects.evaluate(make_input(0.0, 0.1, 1.0, 0.0));
  EXPECT_EQ(enabled_calls, 5);
  EXPECT_EQ(disabled_calls, 0);
  EXPECT_EQ(left_out.name(), "disabled");
}

TEST(EffectSet, FreeCartHasZeroForceAndJacobian) {
  const EffectSet effects;
  const GeneralizedForce total = effects.evaluate(make_input(1.0, 0.3, 2.0, -1.0));
  EXPECT_TRUE(total.force.isZero());
  EXPECT_TRUE(total.jacobian.isZero());
  EXPECT_THROW(EffectSet().add(nullptr), std::invalid_argument);
}

TEST(EffectSet, SumIsTheSumOfTheSingleEffects) {
  const CartModel model{CartParameters{}};
  const EffectSet all = build_effects(birkhoff_cart_test::all_effect_specs(), model);
  for (const EffectInput& input : sample_states()) {
    GeneralizedForce summed;
    for (const EffectSpec& spec : birkhoff_cart_test::all_effect_specs()) {
      const GeneralizedForce one = build_effects({spec}, model).evaluate(input);
      summed.force += one.force;
      summed.jacobian += one.jacobian;
    }
    const GeneralizedForce total = all.evaluate(input);
    EXPECT_TRUE(total.force.isApprox(summed.force, 1e-14));
    EXPECT_TRUE(total.jacobian.isApprox(summed.jacobian, 1e-14));
  }
}

TEST(EffectSet, TheCallersSinAndCosOfTheSteeringAngleGiveTheSameLoadsBitForBit) {
  // The right-hand sides pass sin χ and cos χ they have already computed (EffectInput: one vector
  // call for the stages); the loads must be those the effects compute themselves, bit for bit, or
  // a trajectory would depend on which path evaluated it. 4000 random states, every effect; and a
  // given value is used (a wrong one moves the loads), so the shortcut is not a dead branch.
  const CartModel model{CartParameters{}};
  const EffectSet all = build_effects(birkhoff_cart_test::all_effect_specs(), model);
  std::mt19937_64 random(20261130);
  std::uniform_real_distribution<double> angle(-7.0, 7.0), speed(-8.0, 8.0), rate(-3.0, 3.0), time(0.0, 30.0);
  for (int sample = 0; sample < 4000; ++sample) {
    EffectInput plain = make_input(time(random), angle(random), speed(random), rate(random));
    if (sample % 5 == 0) plain.forward_speed *= 1e-3;  // inside the rolling resistance's tanh band
    EffectInput given = plain;
    given.steering_sin = deterministic::sin(plain.steering_angle);
    given.steering_cos = deterministic::cos(plain.steering_angle);
    const GeneralizedForce computed = all.evaluate(plain);
    const GeneralizedForce shared = all.evaluate(given);
    for (int row = 0; row < 2; ++row) {
      ASSERT_EQ(std::memcmp(&computed.force(row), &shared.force(row), sizeof(double)), 0) << "Q" << row + 1 << " at sample " << sample;
      for (int column = 0; column < 3; ++column) {
        ASSERT_EQ(std::memcmp(&computed.jacobian(row, column), &shared.jacobian(row, column), sizeof(double)), 0)
            << "dQ" << row + 1 << " column " << column << " at sample " << sample;
      }
    }
    if (sample == 0) {
      EffectInput wrong = given;
      wrong.steering_cos = -given.steering_cos;
      EXPECT_NE(all.evaluate(wrong).force(0), computed.force(0)) << "the given cos chi is read";
    }
  }
}

TEST(TorqueSource, RemembersOnlyWhatItsProfileGivesAtThatTimeBitForBit) {
  // A smooth profile's values are remembered by time (torque_source.h): a stage solve asks the same
  // stage times in every iteration. Asked in any order, with repeats, with times that share a memo
  // entry and from a copy, the answer is the profile's own at that time, bit for bit; and a time
  // never asked (a NaN, the empty entries' key) gives the profile's NaN, not a remembered value.
  TorqueProfile cosine;
  cosine.kind = TorqueProfile::Kind::kCosine;
  cosine.amplitude = 3.5;
  cosine.frequency = 0.7;
  cosine.phase = 0.2;
  TorqueProfile switch_off;
  switch_off.kind = TorqueProfile::Kind::kSmoothSwitchOff;
  switch_off.initial = 40.0;
  switch_off.switch_off_time = 4.0;
  switch_off.width = 0.5;
  std::mt19937_64 random(20261130);
  std::uniform_real_distribution<double> time(0.0, 10.0);
  for (const TorqueProfile& profile : {cosine, switch_off}) {
    TorqueSource source(profile);
    std::vector<double> times(64);
    for (double& t : times) t = time(random);
    std::uniform_int_distribution<std::size_t> pick(0, times.size() - 1);
    for (int ask = 0; ask < 5000; ++ask) {
      const double t = times[pick(random)];
      const double expected = profile.at(t);
      const double got = (ask % 7 == 0) ? TorqueSource(source).at(t) : source.at(t);
      ASSERT_EQ(std::memcmp(&expected, &got, sizeof(double)), 0) << "at t = " << t << ", ask " << ask;
    }
    EXPECT_TRUE(std::isnan(TorqueSource(profile).at(std::numeric_limits<double>::quiet_NaN())));
    EXPECT_TRUE(std::isnan(source.at(std::numeric_limits<double>::quiet_NaN())));
  }
}

// ----------------------------------------------------------------------------------------------
// build_effects rejects what it cannot build, naming it.

void expect_rejected(const std::vector<EffectSpec>& specs, const std::vector<std::string>& words) {
  const CartModel model{CartParameters{}};
  try {
    build_effects(specs, model);
    ADD_FAILURE() << "accepted a bad effect list";
  } catch (const std::invalid_argument& error) {
    for (const std::string& word : words) EXPECT_NE(std::string(error.what()).find(word), std::string::npos) << error.what();
  }
}

TEST(BuildEffects, RejectsUnknownNamesAndCoefficientsAndRepeats) {
  // (Each coefficient's range is checked once, by the scene reader: scene_test,
  // EveryEffectCoefficientIsCheckedInItsRowsRange.)
  expect_rejected({coefficient_spec("wind_gust", {})}, {"wind_gust", "unknown effect"});
  expect_rejected({coefficient_spec("air_drug", {{"coefficient", 0.3}})}, {"air_drug", "did you mean 'air_drag'"});
  expect_rejected({coefficient_spec("steering_damping", {})}, {"steering_damping", "missing", "coefficient"});
  expect_rejected({coefficient_spec("rolling_resistance", {{"coefficient", 0.01}})},
                  {"rolling_resistance", "missing", "speed_epsilon"});
  expect_rejected({coefficient_spec("rolling_resistance", {{"coefficient", 0.01}, {"speed_epsilon", 0.05}, {"mu", 1.0}})},
                  {"rolling_resistance", "unknown coefficient", "mu"});
  expect_rejected({coefficient_spec("air_drag", {{"coefficient", 0.3}}), coefficient_spec("air_drag", {{"coefficient", 0.3}})},
                  {"air_drag", "twice"});
  const double nan = std::numeric_limits<double>::quiet_NaN();
  TorqueProfile flat_switch;
  flat_switch.kind = TorqueProfile::Kind::kSmoothSwitchOff;
  flat_switch.initial = 10.0;
  flat_switch.width = 0.0;
  expect_rejected({torque_spec("drive_torque", flat_switch)}, {"drive_torque", "width"});
  expect_rejected({torque_spec("steering_torque", cosine(nan, 1.0, 0.0))}, {"steering_torque", "amplitude"});
  expect_rejected({torque_spec("steering_torque", cosine(1.0, -1.0, 0.0))}, {"steering_torque", "frequency"});
}

}  // namespace
}  // namespace birkhoff_cart
