// The two stage-evaluation paths (vector_math.h) give the same bits: the scalar one is
// deterministic::sin/cos (deterministic_math.h) bit for bit and makes darboux_rates_stages equal
// darboux_rates point by point; the vector one (SLEEF's AVX functions) equals it bit for bit on every
// angle, and the collocation members' trajectories over 100 s of the whirl are the same on both;
// where the CPU lacks AVX the vector path is refused by name. Each test prints what it compared.
// (The integrator property tests run on both paths: CMakeLists.txt runs them again with
// BIRKHOFF_CART_STAGE_EVALUATION=scalar.)
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <stdexcept>
#include <string>

#include "birkhoff_cart/core/physics/cart_birkhoffian.h"
#include "birkhoff_cart/core/cart_binding/cart_stepper.h"
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
