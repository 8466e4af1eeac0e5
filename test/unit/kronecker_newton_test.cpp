// The factored simplified-Newton inverse (kronecker_newton.h, docs/birkhoffian.md eqs. (B.38)–(B.39))
// against the matrix I − hA ⊗ J inverted directly, for s = 1 … 4 Gauss stages, random J with and
// without a zero (cyclic) column, step sizes from small to near-stiff; applied to AD jets too; and a
// singular matrix is reported, not inverted.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "birkhoff_cart/core/integrators/autodiff.h"
#include "birkhoff_cart/core/integrators/gauss_legendre_tableau.h"
#include "birkhoff_cart/core/integrators/kronecker_newton.h"
#include "birkhoff_cart/core/integrators/vector_math.h"

namespace birkhoff_cart {
namespace {

constexpr int kDimension = 4;

/// max |M⁻¹ r (factored) − M⁻¹ r (direct)| / max |M⁻¹ r| over random r.
template <int Stages>
double worst_difference(const Eigen::Matrix4d& jacobian, double h, unsigned cyclic_mask, std::mt19937& random,
                        int* block_size = nullptr) {
  constexpr int kUnknowns = kDimension * Stages;
  const GaussLegendreTableau& tableau = gauss_legendre_tableau(Stages);
  Eigen::Matrix<double, kUnknowns, kUnknowns> matrix = Eigen::Matrix<double, kUnknowns, kUnknowns>::Identity();
  for (int i = 0; i < Stages; ++i) {
    for (int j = 0; j < Stages; ++j) {
      matrix.template block<kDimension, kDimension>(i * kDimension, j * kDimension) -=
          h * tableau.coefficients[i][j] * jacobian;
    }
  }
  const Eigen::Matrix<double, kUnknowns, kUnknowns> direct = matrix.fullPivLu().inverse();
  KroneckerNewtonInverse<kDimension, Stages> factored;
  EXPECT_TRUE(factored.build(jacobian, tableau.coefficients, h, cyclic_mask));
  if (block_size != nullptr) *block_size = factored.block_size();
  std::normal_distribution<double> normal;
  double worst = 0.0;
  for (int trial = 0; trial < 5; ++trial) {
    std::array<double, kUnknowns> residual;
    Eigen::Matrix<double, kUnknowns, 1> r;
    for (int k = 0; k < kUnknowns; ++k) r(k) = residual[k] = normal(random);
    std::array<double, kUnknowns> correction{};
    factored.apply(residual, correction);
    const Eigen::Matrix<double, kUnknowns, 1> expected = direct * r;
    for (int k = 0; k < kUnknowns; ++k) {
      worst = std::max(worst, std::abs(correction[k] - expected(k)) / expected.cwiseAbs().maxCoeff());
    }
  }
  return worst;
}

Eigen::Matrix4d random_jacobian(std::mt19937& random, bool zero_first_column) {
  std::uniform_real_distribution<double> entry(-6.0, 6.0);  // rates up to ~6 /s, as the whirl's
  Eigen::Matrix4d jacobian;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) jacobian(r, c) = entry(random);
  }
  if (zero_first_column) jacobian.col(0).setZero();
  return jacobian;
}

template <int Stages>
void check_stages(double tolerance) {
  std::mt19937 random(7 + Stages);
  for (int trial = 0; trial < 20; ++trial) {
    for (double h : {1e-3, 0.01, 0.05, 0.1}) {
      int block = 0;
      const Eigen::Matrix4d cyclic_free = random_jacobian(random, true);
      EXPECT_LT(worst_difference<Stages>(cyclic_free, h, 1u, random, &block), tolerance) << "h = " << h;
      EXPECT_EQ(block, 3) << "the zero π1 column comes out of the block";
      const Eigen::Matrix4d full = random_jacobian(random, false);
      EXPECT_LT(worst_difference<Stages>(full, h, 1u, random, &block), tolerance) << "h = " << h;
      EXPECT_EQ(block, 4) << "a cyclic column that is not zero keeps every coordinate in the block";
      EXPECT_LT(worst_difference<Stages>(full, h, 0u, random), tolerance) << "h = " << h;
    }
  }
}

constexpr double kTolerance = 1e-11;  // relative; M's condition is O(1) here [-]

TEST(KroneckerNewton, OneStageEqualsTheDirectInverse) { check_stages<1>(kTolerance); }
TEST(KroneckerNewton, TwoStagesEqualTheDirectInverse) { check_stages<2>(kTolerance); }
TEST(KroneckerNewton, ThreeStagesEqualTheDirectInverse) { check_stages<3>(kTolerance); }
TEST(KroneckerNewton, FourStagesEqualTheDirectInverse) { check_stages<4>(kTolerance); }

TEST(KroneckerNewton, AppliesToAutomaticDifferentiationJets) {
  std::mt19937 random(3);
  const Eigen::Matrix4d jacobian = random_jacobian(random, true);
  const GaussLegendreTableau& tableau = gauss_legendre_tableau(3);
  KroneckerNewtonInverse<kDimension, 3> factored;
  ASSERT_TRUE(factored.build(jacobian, tableau.coefficients, 0.05, 1u));
  using Jet = Eigen::AutoDiffScalar<Eigen::Matrix<double, 2, 1>>;
  std::array<Jet, 12> residual;
  std::array<double, 12> values;
  std::array<double, 12> first;
  for (int k = 0; k < 12; ++k) {
    values[k] = std::sin(1.0 + k);
    first[k] = std::cos(2.0 * k);
    residual[k] = Jet(values[k], Eigen::Vector2d(first[k], 0.0));
  }
  std::array<Jet, 12> correction;
  factored.apply(residual, correction);
  std::array<double, 12> value_correction{};
  std::array<double, 12> first_correction{};
  factored.apply(values, value_correction);
  factored.apply(first, first_correction);
  for (int k = 0; k < 12; ++k) {  // linear: the jet's parts are the inverse applied to each part
    EXPECT_NEAR(correction[k].value(), value_correction[k], 1e-14);
    EXPECT_NEAR(correction[k].derivatives()(0), first_correction[k], 1e-14);
    EXPECT_EQ(correction[k].derivatives()(1), 0.0);
  }
}

/// The doubles of an even stage count go through a stages-in-lanes path (SSE2 pairs; for four stages
/// under the vector stage evaluation, one AVX register); a jet's value part through the scalar loops,
/// with the same operations on the values. They must agree to the bit, the shipped runs' results
/// depend on it: on random J (with and without the cyclic column taken out), step sizes and
/// residuals, including a negative first entry (every sum then starts at −0) and a residual with
/// exact zeros. Run once per stage evaluation the CPU offers.
template <int Stages>
void check_paths_agree_bitwise() {
  constexpr int kUnknowns = kDimension * Stages;
  using Jet = Eigen::AutoDiffScalar<Eigen::Matrix<double, 1, 1>>;
  std::mt19937 random(11 + Stages);
  std::normal_distribution<double> normal;
  const GaussLegendreTableau& tableau = gauss_legendre_tableau(Stages);
  int compared = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Matrix4d jacobian = random_jacobian(random, trial % 2 == 0);
    const double h = std::pow(10.0, -3.0 + 3.0 * (trial % 7) / 6.0);  // 1e-3 … 1 s
    KroneckerNewtonInverse<kDimension, Stages> factored;
    if (!factored.build(jacobian, tableau.coefficients, h, 1u)) continue;
    std::array<double, kUnknowns> values;
    std::array<Jet, kUnknowns> jets;
    for (int k = 0; k < kUnknowns; ++k) values[k] = (trial % 5 == 0 && k % 3 == 1) ? 0.0 : normal(random);
    if (trial % 3 == 0) values[0] = -std::abs(values[0]) - 0.5;
    for (int k = 0; k < kUnknowns; ++k) jets[k] = Jet(values[k], Eigen::Matrix<double, 1, 1>(1.0));
    std::array<double, kUnknowns> lanes{};
    std::array<Jet, kUnknowns> scalar;
    factored.apply(values, lanes);
    factored.apply(jets, scalar);
    for (int k = 0; k < kUnknowns; ++k) {
      ASSERT_EQ(std::memcmp(&lanes[k], &scalar[k].value(), sizeof(double)), 0)
          << "entry " << k << " of trial " << trial << ": " << lanes[k] << " against " << scalar[k].value();
    }
    ++compared;
  }
  EXPECT_GT(compared, 190);
}

TEST(KroneckerNewton, TheStageLanesGiveTheScalarLoopsBits) {
  const StageEvaluation before = stage_evaluation();
  std::vector<StageEvaluation> paths{StageEvaluation::kScalar};
  if (vector_stage_evaluation_available()) paths.push_back(StageEvaluation::kVector);
  for (const StageEvaluation path : paths) {
    SCOPED_TRACE("stage evaluation " + to_string(path));
    set_stage_evaluation(path);
    check_paths_agree_bitwise<2>();
    check_paths_agree_bitwise<4>();
  }
  set_stage_evaluation(before);
}

TEST(KroneckerNewton, ReportsASingularMatrix) {
  // J = diag(0, λ, 0, 0) with h a₁₁ λ = 1 for the one stage (a₁₁ = 1/2): I − h a J is singular.
  Eigen::Matrix4d jacobian = Eigen::Matrix4d::Zero();
  jacobian(1, 1) = 4.0;
  KroneckerNewtonInverse<kDimension, 1> factored;
  EXPECT_FALSE(factored.build(jacobian, gauss_legendre_tableau(1).coefficients, 0.5, 1u));
}

}  // namespace
}  // namespace birkhoff_cart
