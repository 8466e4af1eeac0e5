// The Birkhoffian-system concept's analytic members against automatic differentiation of R and B,
// for any model of the concept (birkhoffian_system.h): shared by birkhoffian_system_test (the test
// systems and the cart) and chaplygin_sleigh_test (the example system). Header-only: every
// test/unit/*.cpp is its own executable.
#pragma once

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <string>

#include "birkhoff_cart/core/integrators/autodiff.h"
#include "birkhoff_cart/core/integrators/birkhoffian_system.h"

namespace birkhoff_cart_test {

constexpr double kStructureTolerance = 1e-12;  // relative, Frobenius/max-norm [-]
constexpr double kChartTolerance = 1e-12;      // relative [-]

/// Jet of dimension N+1 over (z, t): z seeded with e_0..e_{N−1}, t with e_N.
template <int N>
struct ZtJets {
  Eigen::Matrix<birkhoff_cart::Jet<N + 1>, N, 1> z;
  birkhoff_cart::Jet<N + 1> t;
  ZtJets(const Eigen::Matrix<double, N, 1>& z_value, double t_value) {
    for (int i = 0; i < N; ++i) z(i) = birkhoff_cart::Jet<N + 1>(z_value(i), N + 1, i);
    t = birkhoff_cart::Jet<N + 1>(t_value, N + 1, N);
  }
};

inline double relative_difference(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).norm() / std::max(b.norm(), 1e-300);
}

/// Checks K_ij = ∂R_j/∂z_i − ∂R_i/∂z_j, K⁻¹ (when given), ∇B, ∂R/∂t, the chart identity
/// D_zᵀ K₀ D_z = K, D⁻¹(D(z)) = z and the chart rates ẇ = D_z ż + ∂_t D at (z, t).
template <class System>
void check_structure_against_ad(const System& system, const Eigen::Matrix<double, System::kDimension, 1>& z,
                                double t, const std::string& label) {
  using namespace birkhoff_cart;
  constexpr int N = System::kDimension;
  SCOPED_TRACE(label);
  const ZtJets<N> jets(z, t);
  const auto r = system.birkhoff_functions(jets.z, jets.t);
  const auto b = system.birkhoffian(jets.z, jets.t);
  Eigen::Matrix<double, N, N> dr_dz;  // (i, j) = ∂R_j/∂z_i
  Eigen::Matrix<double, N, 1> dr_dt;
  for (int j = 0; j < N; ++j) {
    dr_dz.col(j) = r(j).derivatives().template head<N>();
    dr_dt(j) = r(j).derivatives()(N);
  }
  const Eigen::Matrix<double, N, N> k_ad = dr_dz - dr_dz.transpose();
  const Eigen::Matrix<double, N, N> k = system.structure_matrix(z, t);
  EXPECT_LE(relative_difference(k, k_ad), kStructureTolerance) << "K\n" << k << "\nAD\n" << k_ad;
  if constexpr (birkhoffian_system_detail::HasStructureMatrixInverse<System, double>::value) {
    const Eigen::Matrix<double, N, N> k_inverse = system.structure_matrix_inverse(z, t);  // analytic K⁻¹
    EXPECT_LE(relative_difference(k_inverse * k, Eigen::Matrix<double, N, N>::Identity()), kStructureTolerance);
  }
  const Eigen::Matrix<double, N, 1> gradient = system.birkhoffian_gradient(z, t);
  EXPECT_LE(relative_difference(gradient, b.derivatives().template head<N>()), kStructureTolerance)
      << gradient.transpose() << " vs AD " << b.derivatives().transpose();
  const Eigen::Matrix<double, N, 1> r_t = system.birkhoff_functions_time_derivative(z, t);
  EXPECT_LE((r_t - dr_dt).norm(), kStructureTolerance * std::max(1.0, dr_dt.norm()))
      << r_t.transpose() << " vs AD " << dr_dt.transpose();

  // Chart: D_zᵀ K₀ D_z = K, D⁻¹(D(z)) = z, ẇ = D_z ż + ∂_t D.
  const auto w_jet = system.to_darboux(jets.z, jets.t);
  Eigen::Matrix<double, N, N> d_z;
  Eigen::Matrix<double, N, 1> d_t, w;
  for (int i = 0; i < N; ++i) {
    w(i) = w_jet(i).value();
    d_z.row(i) = w_jet(i).derivatives().template head<N>().transpose();
    d_t(i) = w_jet(i).derivatives()(N);
  }
  const Eigen::Matrix<double, N, N> k0 = canonical_structure<N>();
  EXPECT_LE(relative_difference(d_z.transpose() * k0 * d_z, k), kChartTolerance);
  const Eigen::Matrix<double, N, 1> z_back = system.from_darboux(w, t);
  EXPECT_LE((z_back - z).norm(), kChartTolerance * std::max(1.0, z.norm()));
  const Eigen::Matrix<double, N, 1> z_rate = birkhoffian_rates(system, z, t);
  const Eigen::Matrix<double, N, 1> w_rate = system.darboux_rates(w, t);
  const Eigen::Matrix<double, N, 1> expected = d_z * z_rate + d_t;
  EXPECT_LE((w_rate - expected).norm(), kChartTolerance * std::max(1.0, expected.norm()))
      << w_rate.transpose() << " vs " << expected.transpose();
}

}  // namespace birkhoff_cart_test
