// The two stage-evaluation paths (vector_math.h): the scalar one is std::sin/std::cos bit for bit and
// makes darboux_rates_stages equal darboux_rates point by point; the vector one (AVX2 libmvec)
// agrees with it to a few ulp per angle and the collocation members' trajectories to round-off over
// 100 s of the whirl; where the CPU lacks AVX2 the vector path is refused by name. (The
// integrator property tests run on both paths: CMakeLists.txt runs them again with
// BIRKHOFF_CART_STAGE_EVALUATION=scalar.)
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <stdexcept>
#include <string>

#include "birkhoff_cart/core/cart_birkhoffian.h"
#include "birkhoff_cart/core/cart_binding/cart_stepper.h"
#include "birkhoff_cart/core/scene.h"
#include "birkhoff_cart/core/vector_math.h"
#include "generated_docs.h"

namespace birkhoff_cart {
namespace {

/// Restores the process's path after each test.
class StageEvaluationTest : public ::testing::Test {
 protected:
  void TearDown() override { set_stage_evaluation(initial_); }
  const StageEvaluation initial_ = stage_evaluation();
};

/// |a − b| in units in the last place of a.
double ulps(double a, double b) { return std::abs(a - b) / std::abs(std::nextafter(a, 2.0 * a + 1.0) - a); }

/// sin_cos_lanes on 1000 random batches of 1 … kMaxVectorLanes angles in [−10, 10] rad, with
/// check(angle, sine, cosine) on every lane.
template <class Check>
void for_random_batches(unsigned seed, Check check) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> angle(-10.0, 10.0);
  for (int trial = 0; trial < 1000; ++trial) {
    double angles[kMaxVectorLanes];
    double sines[kMaxVectorLanes];
    double cosines[kMaxVectorLanes];
    const int count = 1 + trial % kMaxVectorLanes;
    for (int i = 0; i < count; ++i) angles[i] = angle(random);
    sin_cos_lanes(angles, count, sines, cosines);
    for (int i = 0; i < count; ++i) check(angles[i], sines[i], cosines[i]);
  }
}

TEST_F(StageEvaluationTest, ScalarPathIsTheStandardLibraryBitForBit) {
  set_stage_evaluation(StageEvaluation::kScalar);
  for_random_batches(5, [](double angle, double sine, double cosine) {
    EXPECT_EQ(sine, std::sin(angle));
    EXPECT_EQ(cosine, std::cos(angle));
  });
}

TEST_F(StageEvaluationTest, VectorPathAgreesToAFewUlpOrIsRefusedByName) {
  if (!vector_stage_evaluation_available()) {
    try {
      set_stage_evaluation(StageEvaluation::kVector);
      FAIL() << "the vector path was accepted on a CPU without AVX2";
    } catch (const std::invalid_argument& error) {
      EXPECT_NE(std::string(error.what()).find("AVX2"), std::string::npos) << error.what();
    }
    EXPECT_EQ(stage_evaluation(), StageEvaluation::kScalar);
    return;
  }
  set_stage_evaluation(StageEvaluation::kVector);
  EXPECT_EQ(stage_evaluation(), StageEvaluation::kVector);
  double worst = 0.0;
  for_random_batches(6, [&worst](double angle, double sine, double cosine) {
    // libmvec's bound is 4 ulp of the exact value; std::sin/std::cos are within 1.
    worst = std::max({worst, ulps(std::sin(angle), sine), ulps(std::cos(angle), cosine)});
  });
  EXPECT_LE(worst, 5.0);
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

TEST_F(StageEvaluationTest, TrajectoriesOfBothPathsAgreeToRoundOff) {
  if (!vector_stage_evaluation_available()) GTEST_SKIP() << "no AVX2: one path only";
  double largest = 0.0;  // the paths' largest distance of B after 100 s [m]
  for (const char* integrator : {"birkhoff_gauss4", "birkhoff_gauss6", "birkhoff_gauss8", "birkhoff8_kahan_li"}) {
    set_stage_evaluation(StageEvaluation::kScalar);
    const CartState scalar = whirl(integrator, 100.0);
    set_stage_evaluation(StageEvaluation::kVector);
    const CartState vector = whirl(integrator, 100.0);
    // Round-off: the paths differ by ≤ 4 ulp per sine.
    const double distance = std::hypot(scalar.x - vector.x, scalar.y - vector.y);
    std::printf("[ measured ] %s, whirl 100 s at h = 0.02 s: scalar vs vector path %.3e m\n", integrator, distance);
    largest = std::max(largest, distance);
    EXPECT_LT(distance, 1e-11) << integrator;
    EXPECT_LT(std::abs(scalar.steering_angle - vector.steering_angle), 1e-10) << integrator;
    EXPECT_LT(std::abs(scalar.forward_speed - vector.forward_speed), 1e-10) << integrator;
  }
  // docs/integrators.md and docs/birkhoffian.md §10.6 quote the largest (one digit).
  EXPECT_TRUE(birkhoff_cart_test::page_figure_agrees("docs/integrators.md", "libm to 1): ", 0, largest, 0.25));
  EXPECT_TRUE(birkhoff_cart_test::page_figure_agrees("docs/birkhoffian.md", "give trajectories that agree to round-off (", 0,
                                                     largest, 0.25));
}

}  // namespace
}  // namespace birkhoff_cart
