// The two stage-evaluation paths (vector_math.h) give the same bits: the scalar one is
// deterministic::sin/cos (deterministic_math.h) bit for bit and makes darboux_rates_stages equal
// darboux_rates point by point; the vector one (SLEEF's AVX functions) equals it bit for bit on every
// angle, and the collocation members' trajectories over 100 s of the whirl are the same on both;
// where the CPU lacks AVX the vector path is refused by name. Each test prints what it compared.
// (The integrator property tests run on both paths: CMakeLists.txt runs them again with
// BIRKHOFF_CART_STAGE_EVALUATION=scalar.)
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "all_effects.h"
#include "birkhoff_cart/core/physics/cart_birkhoffian.h"
#include "birkhoff_cart/core/physics/effect_library.h"
#include "birkhoff_cart/core/cart_binding/cart_stepper.h"
#include "birkhoff_cart/core/integrators/gauss_collocation.h"
#include "birkhoff_cart/core/integrators/time_transformed_system.h"
#include "birkhoff_cart/core/integrators/deterministic_math.h"
#include "birkhoff_cart/core/scene/scene.h"
#include "birkhoff_cart/core/integrators/vector_math.h"
#include "generated_docs.h"

namespace birkhoff_cart {
namespace {

/// Restores the process's path after each test.
class StageEvaluationTest : public ::testing::Test {
 protected:
  void TearDown() override { set_stage_evaluation(initial_); }
  const StageEvaluation initial_ = stage_evaluation();
};

/// Do a and b have the same bits (so that 0.0 and −0.0 differ, and a NaN equals itself)?
bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

constexpr int kBatches = 100000;

/// sin_cos_lanes on kBatches random batches of 1 … kMaxVectorLanes angles, in [−10, 10] rad and
/// (every third batch) in [−0.01, 0.01] rad, with check(angle, sine, cosine) on every lane.
template <class Check>
void for_random_batches(unsigned seed, Check check) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> angle(-10.0, 10.0);
  for (int trial = 0; trial < kBatches; ++trial) {
    const double scale = trial % 3 == 0 ? 1e-3 : 1.0;
    double angles[kMaxVectorLanes];
    double sines[kMaxVectorLanes];
    double cosines[kMaxVectorLanes];
    const int count = 1 + trial % kMaxVectorLanes;
    for (int i = 0; i < count; ++i) angles[i] = scale * angle(random);
    sin_cos_lanes(angles, count, sines, cosines);
    for (int i = 0; i < count; ++i) check(angles[i], sines[i], cosines[i]);
  }
}

TEST_F(StageEvaluationTest, ScalarPathIsTheDeterministicFunctionsBitForBit) {
  set_stage_evaluation(StageEvaluation::kScalar);
  long differing = 0;
  for_random_batches(5, [&differing](double angle, double sine, double cosine) {
    differing += !same_bits(sine, deterministic::sin(angle)) + !same_bits(cosine, deterministic::cos(angle));
  });
  std::printf("[ compared ] scalar path vs deterministic::sin/cos, bits of %d batches of 1-4 angles: %ld differ\n",
              kBatches, differing);
  EXPECT_EQ(differing, 0);
}

TEST_F(StageEvaluationTest, VectorPathGivesTheScalarPathsBitsOrIsRefusedByName) {
  if (!vector_stage_evaluation_available()) {
    try {
      set_stage_evaluation(StageEvaluation::kVector);
      FAIL() << "the vector path was accepted on a CPU without AVX";
    } catch (const std::invalid_argument& error) {
      EXPECT_NE(std::string(error.what()).find("AVX"), std::string::npos) << error.what();
    }
    EXPECT_EQ(stage_evaluation(), StageEvaluation::kScalar);
    return;
  }
  set_stage_evaluation(StageEvaluation::kVector);
  EXPECT_EQ(stage_evaluation(), StageEvaluation::kVector);
  long differing = 0;
  for_random_batches(6, [&differing](double angle, double sine, double cosine) {
    differing += !same_bits(sine, deterministic::sin(angle)) + !same_bits(cosine, deterministic::cos(angle));
  });
  std::printf("[ compared ] vector path vs scalar path, bits of %d batches of 1-4 angles: %ld differ\n", kBatches,
              differing);
  EXPECT_EQ(differing, 0);
}

/// tanh_lanes on both paths against deterministic::tanh, on kBatches random batches of 1 …
/// kMaxVectorLanes arguments: rim speed ratios in [−40, 40] (a wheel far beyond the band), in [−1, 1]
/// (within it) and in [−1e-6, 1e-6] (at rest), and ±0, ±∞ and NaN. Returns the lanes that differ.
long tanh_lanes_differing_from_scalar(unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  long differing = 0;
  const double scales[3] = {40.0, 1.0, 1e-6};
  for (int trial = 0; trial < kBatches; ++trial) {
    double x[kMaxVectorLanes];
    double out[kMaxVectorLanes];
    const int count = 1 + trial % kMaxVectorLanes;
    for (int i = 0; i < count; ++i) x[i] = scales[trial % 3] * unit(random);
    tanh_lanes(x, count, out);
    for (int i = 0; i < count; ++i) differing += !same_bits(out[i], deterministic::tanh(x[i]));
  }
  const double special[kMaxVectorLanes] = {0.0, -0.0, INFINITY, NAN};
  double out[kMaxVectorLanes];
  tanh_lanes(special, kMaxVectorLanes, out);
  for (int i = 0; i < kMaxVectorLanes; ++i) differing += !same_bits(out[i], deterministic::tanh(special[i]));
  return differing;
}

TEST_F(StageEvaluationTest, TanhLanesGiveTheDeterministicTanhsBitsOnBothPaths) {
  set_stage_evaluation(StageEvaluation::kScalar);
  const long scalar_differing = tanh_lanes_differing_from_scalar(7);
  std::printf("[ compared ] tanh_lanes scalar path vs deterministic::tanh, %d batches of 1-4: %ld differ\n",
              kBatches, scalar_differing);
  EXPECT_EQ(scalar_differing, 0);
  if (!vector_stage_evaluation_available()) GTEST_SKIP() << "no AVX: one path only";
  set_stage_evaluation(StageEvaluation::kVector);
  const long vector_differing = tanh_lanes_differing_from_scalar(8);
  std::printf("[ compared ] tanh_lanes vector path vs deterministic::tanh, %d batches of 1-4: %ld differ\n",
              kBatches, vector_differing);
  EXPECT_EQ(vector_differing, 0);
}

// The step controls take a step's two powers from one call (adaptive_step_control.h): each lane
// must be deterministic::pow's bits, over the ranges a control asks (error ratios from round-off to
// far beyond the aim, exponents ±1/k) and beyond, with exact zeros, ones and a NaN among them.
TEST_F(StageEvaluationTest, PowPairGivesTheDeterministicPowsBits) {
  std::mt19937 random(17);
  std::uniform_real_distribution<double> log_base(-40.0, 12.0);
  std::uniform_real_distribution<double> exponent(-2.0, 2.0);
  long differing = 0;
  constexpr int kPairs = 200000;
  for (int trial = 0; trial < kPairs; ++trial) {
    std::array<double, 2> x{std::exp(log_base(random)), std::exp(log_base(random))};
    std::array<double, 2> power{exponent(random), 1.0 / (1 + trial % 9)};
    if (trial % 7 == 0) x[0] = 0.0;
    if (trial % 11 == 0) x[1] = 1.0;
    if (trial % 13 == 0) power[0] = -power[0];
    if (trial == 5) x[1] = std::nan("");
    const std::array<double, 2> pair = deterministic::pow_pair(x, power);
    for (int lane = 0; lane < 2; ++lane) {
      if (!same_bits(pair[lane], deterministic::pow(x[lane], power[lane]))) ++differing;
    }
  }
  std::printf("[ compared ] pow_pair vs deterministic::pow, %d pairs: %ld lanes differ\n", kPairs, differing);
  EXPECT_EQ(differing, 0);
}

TEST_F(StageEvaluationTest, StageRatesOnTheScalarPathAreThePointwiseRates) {
  set_stage_evaluation(StageEvaluation::kScalar);
  const CartModel model{CartParameters{}};
  const EffectSet effects;
  const CartAutonomousBirkhoffian autonomous(model, effects);
  CartPaperBirkhoffian paper(model, effects);
  paper.begin_step(2.0);
  std::mt19937 random(8);
  std::uniform_real_distribution<double> steering(-1.4, 1.4), momentum(-300.0, 300.0);
  std::array<Eigen::Vector4d, 3> points;
  std::array<double, 3> times = {2.0, 2.01, 2.02};
  for (auto& point : points) point = Eigen::Vector4d(1.0, steering(random), momentum(random), momentum(random) / 10);
  std::array<Eigen::Vector4d, 3> rates;
  autonomous.darboux_rates_stages(points, times, rates);
  for (int j = 0; j < 3; ++j) EXPECT_EQ(rates[j], autonomous.darboux_rates(points[j], times[j]));
  paper.darboux_rates_stages(points, times, rates);
  for (int j = 0; j < 3; ++j) EXPECT_EQ(rates[j], paper.darboux_rates(points[j], times[j]));
}

/// Bits of the passive rates of `stages` against `pointwise`: the entries that differ.
template <class Passive, std::size_t Count>
long differing_entries(const std::array<Passive, Count>& stages, const std::array<Passive, Count>& pointwise) {
  long differing = 0;
  for (std::size_t j = 0; j < Count; ++j) {
    for (int k = 0; k < Passive::RowsAtCompileTime; ++k) differing += !same_bits(stages[j](k), pointwise[j](k));
  }
  return differing;
}

/// passive_rates_stages, passive_coupling_rates_stages and darboux_rates_stages of `system` (the
/// cart, or the cart in fictive time, whose rates divide by the step density of each stage) against
/// passive_rates, passive_coupling_rates and darboux_rates stage by stage, on `trials` random sets of
/// four stages: the entries whose bits differ.
template <class System>
long passive_stage_rates_differing(const System& system, unsigned seed, int trials) {
  using Vector = typename System::template Vector<double>;
  using Passive = typename System::template Passive<double>;
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> steering(-1.4, 1.4), momentum(-300.0, 300.0), heading(-40.0, 40.0),
      unit(-1.0, 1.0);
  long differing = 0;
  for (int trial = 0; trial < trials; ++trial) {
    std::array<Vector, 4> points;
    std::array<Passive, 4> passive;
    std::array<double, 4> times;
    for (int j = 0; j < 4; ++j) {
      points[j] = Vector(unit(random), steering(random), momentum(random), momentum(random) / 10);
      passive[j] = Passive::Constant(0.0);
      for (int k = 0; k < Passive::RowsAtCompileTime; ++k) passive[j](k) = 10.0 * unit(random);
      passive[j](kHeadingIndex) = heading(random);
      times[j] = 2.0 + 0.01 * j;
    }
    std::array<Passive, 4> together;
    std::array<Passive, 4> one_by_one;
    system.passive_rates_stages(points, passive, times, together);
    for (int j = 0; j < 4; ++j) one_by_one[j] = system.passive_rates(points[j], passive[j], times[j]);
    differing += differing_entries(together, one_by_one);
    system.passive_coupling_rates_stages(points, times, together);
    for (int j = 0; j < 4; ++j) one_by_one[j] = system.passive_coupling_rates(points[j], times[j]);
    differing += differing_entries(together, one_by_one);
    std::array<Vector, 4> rates_together;
    std::array<Vector, 4> rates_one_by_one;
    system.darboux_rates_stages(points, times, rates_together);
    for (int j = 0; j < 4; ++j) rates_one_by_one[j] = system.darboux_rates(points[j], times[j]);
    differing += differing_entries(rates_together, rates_one_by_one);
  }
  return differing;
}

/// The cart under every load (so that the work and impulse rates read them), in time and in the
/// reversible control's fictive time (a stiff density 400 s⁻² as a hinge spring's), built in place:
/// its systems point at its own model and effects.
struct LoadedCart {
  LoadedCart() = default;
  LoadedCart(const LoadedCart&) = delete;
  LoadedCart& operator=(const LoadedCart&) = delete;
  const CartModel model{CartParameters{}};
  const EffectSet effects = build_effects(birkhoff_cart_test::all_effect_specs(), model);
  const CartAutonomousBirkhoffian autonomous{model, effects};
  const TimeTransformedSystem<CartAutonomousBirkhoffian> fictive{autonomous, 2.0, 400.0};
};

// The passive quadrature's one call a sweep (passive_quadrature.h) is g stage by stage bit for bit,
// with every load on (so the work and impulse rates read them), on both paths, for the cart in
// time and in the reversible control's fictive time (there the stages' step densities come from one
// call too, in the rates of every iteration).
TEST_F(StageEvaluationTest, PassiveStageRatesAreThePointwiseRatesBitForBitOnBothPaths) {
  const LoadedCart cart;
  CartPaperBirkhoffian paper(cart.model, cart.effects);
  paper.begin_step(2.0);
  std::vector<StageEvaluation> paths = {StageEvaluation::kScalar};
  if (vector_stage_evaluation_available()) paths.push_back(StageEvaluation::kVector);
  for (const StageEvaluation path : paths) {
    set_stage_evaluation(path);
    const long in_time =
        passive_stage_rates_differing(cart.autonomous, 11, 2000) + passive_stage_rates_differing(paper, 12, 2000);
    const long in_fictive_time = passive_stage_rates_differing(cart.fictive, 13, 2000);
    std::printf("[ compared ] %s path: passive rates of 2000 x 4 stages together vs one by one, bits of every entry: "
                "%ld differ in time, %ld in fictive time (with its stage rates)\n",
                to_string(path).c_str(), in_time, in_fictive_time);
    EXPECT_EQ(in_time, 0);
    EXPECT_EQ(in_fictive_time, 0);
  }
}

/// darboux_and_passive_rates of `system` against darboux_rates and passive_rates at `trials` random
/// points: the entries whose bits differ.
template <class System>
long shared_end_rates_differing(const System& system, unsigned seed, int trials) {
  using Vector = typename System::template Vector<double>;
  using Passive = typename System::template Passive<double>;
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> steering(-1.4, 1.4), momentum(-300.0, 300.0), unit(-1.0, 1.0);
  long differing = 0;
  for (int trial = 0; trial < trials; ++trial) {
    const Vector w(unit(random), steering(random), momentum(random), momentum(random) / 10);
    Passive y = Passive::Constant(0.0);
    for (int k = 0; k < Passive::RowsAtCompileTime; ++k) y(k) = 10.0 * unit(random);
    const double t = 2.0 + unit(random);
    Vector rate;
    Passive passive;
    system.darboux_and_passive_rates(w, y, t, rate, passive);
    const Vector rate_alone = system.darboux_rates(w, t);
    const Passive passive_alone = system.passive_rates(w, y, t);
    for (int k = 0; k < Vector::RowsAtCompileTime; ++k) differing += !same_bits(rate(k), rate_alone(k));
    for (int k = 0; k < Passive::RowsAtCompileTime; ++k) differing += !same_bits(passive(k), passive_alone(k));
  }
  return differing;
}

// The local error estimate's F(w⁺) and g(z⁺, y⁺) from one shared evaluation (collocation_error_estimate.h)
// are the two calls bit for bit: under every load, with the non-Birkhoffian force off, and in the
// reversible control's fictive time.
TEST_F(StageEvaluationTest, SharedEndRatesAreTheTwoCallsBitForBit) {
  const LoadedCart cart;
  CartAutonomousBirkhoffian force_off(cart.model, cart.effects);
  force_off.set_non_birkhoffian_force_enabled(false);
  const long in_time =
      shared_end_rates_differing(cart.autonomous, 21, 4000) + shared_end_rates_differing(force_off, 22, 4000);
  const long in_fictive_time = shared_end_rates_differing(cart.fictive, 23, 4000);
  std::printf("[ compared ] darboux_and_passive_rates vs darboux_rates and passive_rates at 3 x 4000 points, bits of "
              "every entry: %ld differ in time (loads on and off), %ld in fictive time\n",
              in_time, in_fictive_time);
  EXPECT_EQ(in_time, 0);
  EXPECT_EQ(in_fictive_time, 0);
}

/// The cart with every hook but its shared evaluations, which it hides: the passive quadrature then
/// evaluates g stage by stage, and the local error estimate F(w⁺) and g(z⁺, y⁺) apart.
class CartWithoutSharedRates : public CartAutonomousBirkhoffian {
 public:
  using CartAutonomousBirkhoffian::CartAutonomousBirkhoffian;
  void passive_rates_stages() const = delete;
  void passive_coupling_rates_stages() const = delete;
  void darboux_and_passive_rates() const = delete;
};

// A whole collocation run with the shared evaluations (the stage-batched passive rates, the end
// rates of the local error estimate) is the run without them, bit for bit, estimate included: the
// hooks change the cost only (gauss8, 160 steps of 0.05 s under every load).
TEST_F(StageEvaluationTest, PassiveQuadratureWithTheStageHookIsTheRunWithoutItBitForBit) {
  static_assert(system_traits::kHasPassiveStageRates<CartAutonomousBirkhoffian, 4>);
  static_assert(system_traits::kHasDarbouxAndPassiveRates<CartAutonomousBirkhoffian>);
  static_assert(!system_traits::kHasPassiveStageRates<CartWithoutSharedRates, 4>);
  static_assert(!system_traits::kHasDarbouxAndPassiveRates<CartWithoutSharedRates>);
  const LoadedCart cart;
  const CartAutonomousBirkhoffian& with_hook = cart.autonomous;
  const CartWithoutSharedRates without_hook(cart.model, cart.effects);
  const GaussCollocation<4> gauss8;
  Eigen::Vector4d z_with(0.0, 0.3, 40.0, 2.0);
  Eigen::Matrix<double, CartAutonomousBirkhoffian::kPassiveDimension, 1> y_with =
      Eigen::Matrix<double, CartAutonomousBirkhoffian::kPassiveDimension, 1>::Zero();
  y_with(kHeadingIndex) = 0.5;
  Eigen::Vector4d z_without = z_with;
  auto y_without = y_with;
  StepStatistics with_statistics;
  StepStatistics without_statistics;
  for (int k = 0; k < 160; ++k) {
    gauss8.step(with_hook, z_with, y_with, 0.05 * k, 0.05, with_statistics);
    gauss8.step(without_hook, z_without, y_without, 0.05 * k, 0.05, without_statistics);
  }
  long differing = 0;
  for (int k = 0; k < 4; ++k) differing += !same_bits(z_with(k), z_without(k));
  for (int k = 0; k < y_with.size(); ++k) differing += !same_bits(y_with(k), y_without(k));
  differing += !same_bits(with_statistics.local_error_estimate_max, without_statistics.local_error_estimate_max);
  differing += !same_bits(with_statistics.local_error_estimate_sum, without_statistics.local_error_estimate_sum);
  std::printf("[ compared ] gauss8, 160 steps under every load: bits of z, y and the estimate's max and sum with and "
              "without the shared evaluations: %ld of %d differ (x %.17g m, largest estimate %.3g); passive "
              "evaluations %llu and %llu\n",
              differing, 6 + static_cast<int>(y_with.size()), y_with(0), with_statistics.local_error_estimate_max,
              static_cast<unsigned long long>(with_statistics.passive_evaluations),
              static_cast<unsigned long long>(without_statistics.passive_evaluations));
  EXPECT_EQ(differing, 0);
  EXPECT_EQ(with_statistics.passive_evaluations, without_statistics.passive_evaluations);
  EXPECT_TRUE(std::isfinite(y_with(0)) && y_with(0) != 0.0) << "the run moved nowhere: nothing compared";
  EXPECT_GT(with_statistics.local_error_estimate_max, 0.0) << "no estimate was made: the end rates were not compared";
}

/// The whirl over `duration` [s] with `integrator` at h = 0.02 s on the path in use.
CartState whirl(const std::string& integrator, double duration) {
  const Scene scene = load_scene(std::string(BIRKHOFF_CART_SOURCE_DIR) + "/config/scenes/jackknife_whirl.yaml");
  const CartModel model(scene.cart);
  const EffectSet effects;
  IntegratorSettings settings = scene.integrator;
  settings.name = integrator;
  settings.step_size = 0.02;
  const auto stepper = make_cart_stepper(settings, model, effects);
  CartState state = scene.initial_state;
  StepStatistics statistics;
  const long steps = std::lround(duration / settings.step_size);
  for (long k = 1; k <= steps; ++k) {
    stepper->step(state, settings.step_size, statistics);
    state.time = scene.initial_state.time + static_cast<double>(k) * settings.step_size;
  }
  return state;
}

TEST_F(StageEvaluationTest, TrajectoriesOfBothPathsAreTheSameBitForBit) {
  if (!vector_stage_evaluation_available()) GTEST_SKIP() << "no AVX: one path only";
  for (const char* integrator : {"birkhoff_gauss4", "birkhoff_gauss6", "birkhoff_gauss8", "birkhoff8_kahan_li"}) {
    set_stage_evaluation(StageEvaluation::kScalar);
    const CartState scalar = whirl(integrator, 100.0);
    set_stage_evaluation(StageEvaluation::kVector);
    const CartState vector = whirl(integrator, 100.0);
    const bool same = same_bits(scalar.x, vector.x) && same_bits(scalar.y, vector.y) &&
                      same_bits(scalar.heading, vector.heading) && same_bits(scalar.steering_angle, vector.steering_angle) &&
                      same_bits(scalar.forward_speed, vector.forward_speed) &&
                      same_bits(scalar.steering_rate, vector.steering_rate);
    std::printf("[ compared ] %s, whirl 100 s at h = 0.02 s: bits of x, y, θ, χ, ω1, ω2 on the scalar and vector "
                "paths: %s (x %.17g vs %.17g m)\n",
                integrator, same ? "the same" : "DIFFER", scalar.x, vector.x);
    EXPECT_TRUE(same) << integrator;
  }
}

}  // namespace
}  // namespace birkhoff_cart
