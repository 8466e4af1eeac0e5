// Gauss–Legendre tableaus computed in long double (see the header).
#include "birkhoff_cart/core/integrators/gauss_legendre_tableau.h"

#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

namespace birkhoff_cart {
namespace {

using Real = long double;

/// Legendre polynomial P_s(x) on [−1, 1] and its derivative, by the three-term recurrence.
void legendre(int s, Real x, Real& value, Real& derivative) {
  Real p_previous = 1.0L;
  Real p = x;
  if (s == 0) {
    value = 1.0L;
    derivative = 0.0L;
    return;
  }
  for (int k = 2; k <= s; ++k) {
    const Real p_next = ((2 * k - 1) * x * p - (k - 1) * p_previous) / k;
    p_previous = p;
    p = p_next;
  }
  value = p;
  derivative = s * (x * p - p_previous) / (x * x - 1.0L);
}

/// Roots of P_s on (−1, 1), ascending, by Newton from Chebyshev-like guesses.
std::array<Real, kMaxGaussStages> legendre_roots(int s) {
  std::array<Real, kMaxGaussStages> roots{};
  const Real pi = 3.141592653589793238462643383279502884L;
  for (int i = 0; i < s; ++i) {
    Real x = -std::cos(pi * (i + 0.75L) / (s + 0.5L));
    for (int iteration = 0; iteration < 100; ++iteration) {
      Real value = 0.0L;
      Real derivative = 0.0L;
      legendre(s, x, value, derivative);
      const Real update = value / derivative;
      x -= update;
      if (std::fabs(update) < 1e-30L) break;
    }
    roots[i] = x;
  }
  return roots;
}

/// ℓⱼ(τ) on `points` (count of them), in the arithmetic of Number (long double for the tableau).
template <class Point, class Number = Real>
Number lagrange_basis(const std::array<Point, kMaxGaussStages>& points, int count, int j, Number tau) {
  Number value = 1.0;
  for (int m = 0; m < count; ++m) {
    if (m != j) value *= (tau - points[m]) / (static_cast<Number>(points[j]) - points[m]);
  }
  return value;
}

/// ∫_{from}^{to} ℓⱼ with the 2-point Gauss rule on [from, to]: exact for degree ≤ 3.
template <class Point>
Real integrate_basis(const std::array<Point, kMaxGaussStages>& points, int count, int j, Real from, Real to) {
  const Real half = 0.5L * (to - from);
  const Real mid = 0.5L * (to + from);
  const Real offset = half / std::sqrt(3.0L);
  return half * (lagrange_basis(points, count, j, mid - offset) + lagrange_basis(points, count, j, mid + offset));
}

GaussLegendreTableau compute_tableau(int s) {
  GaussLegendreTableau tableau;
  tableau.stages = s;
  const std::array<Real, kMaxGaussStages> roots = legendre_roots(s);
  std::array<Real, kMaxGaussStages> nodes{};
  for (int i = 0; i < s; ++i) nodes[i] = 0.5L * (roots[i] + 1.0L);  // cᵢ = (xᵢ + 1)/2
  for (int i = 0; i < s; ++i) {
    tableau.nodes[i] = static_cast<double>(nodes[i]);
    for (int j = 0; j < s; ++j) {
      tableau.coefficients[i][j] = static_cast<double>(integrate_basis(nodes, s, j, 0.0L, nodes[i]));
    }
  }
  std::array<std::array<Real, kMaxGaussStages>, kMaxGaussStages> a{};
  std::array<Real, kMaxGaussStages> b{};
  for (int j = 0; j < s; ++j) {
    b[j] = integrate_basis(nodes, s, j, 0.0L, 1.0L);
    tableau.weights[j] = static_cast<double>(b[j]);
    for (int i = 0; i < s; ++i) a[i][j] = integrate_basis(nodes, s, j, 0.0L, nodes[i]);
  }
  // d solves Aᵀ d = b (Gaussian elimination with partial pivoting, long double).
  std::array<std::array<Real, kMaxGaussStages + 1>, kMaxGaussStages> system{};
  for (int i = 0; i < s; ++i) {
    for (int j = 0; j < s; ++j) system[i][j] = a[j][i];
    system[i][s] = b[i];
  }
  for (int column = 0; column < s; ++column) {
    int pivot = column;
    for (int row = column + 1; row < s; ++row) {
      if (std::fabs(system[row][column]) > std::fabs(system[pivot][column])) pivot = row;
    }
    std::swap(system[column], system[pivot]);
    for (int row = 0; row < s; ++row) {
      if (row == column) continue;
      const Real factor = system[row][column] / system[column][column];
      for (int k = column; k <= s; ++k) system[row][k] -= factor * system[column][k];
    }
  }
  Real increment_weight_sum = 0.0L;
  for (int i = 0; i < s; ++i) {
    const Real weight = system[i][s] / system[i][i];
    tableau.increment_weights[i] = static_cast<double>(weight);
    increment_weight_sum += weight;
  }
  tableau.remainder_weight = static_cast<double>(std::round(1.0L - increment_weight_sum));  // (−1)^s exactly

  // Embedded weights on {0, c₁ … c_s, 1} (eq. (B.36)): endpoint weights ±β, β = 1/((s+1)(s+2)), with
  // the sign (−1)^{s+1} that makes the rule exact to degree s; interior ones from exactness to s − 1.
  const Real beta = 1.0L / static_cast<Real>((s + 1) * (s + 2));
  const Real end_sign = (s % 2 == 1) ? 1.0L : -1.0L;
  tableau.embedded_weights[0] = static_cast<double>(beta);
  tableau.embedded_weights[s + 1] = static_cast<double>(end_sign * beta);
  tableau.estimate_weights[0] = static_cast<double>(-beta);
  tableau.estimate_weights[s + 1] = static_cast<double>(-end_sign * beta);
  for (int j = 0; j < s; ++j) {
    const Real defect_weight = beta * (lagrange_basis(nodes, s, j, 0.0L) + end_sign * lagrange_basis(nodes, s, j, 1.0L));
    tableau.embedded_weights[j + 1] = static_cast<double>(b[j] - defect_weight);
    tableau.estimate_weights[j + 1] = static_cast<double>(defect_weight);  // bⱼ − b̂ⱼ
  }
  return tableau;
}

}  // namespace

const GaussLegendreTableau& gauss_legendre_tableau(int stages) {
  static const std::array<GaussLegendreTableau, kMaxGaussStages> tableaus = {compute_tableau(1), compute_tableau(2),
                                                                             compute_tableau(3), compute_tableau(4)};
  if (stages < 1 || stages > kMaxGaussStages) {
    throw std::invalid_argument("Gauss–Legendre collocation has 1 to 4 stages here, got " + std::to_string(stages));
  }
  return tableaus[stages - 1];
}

std::array<double, kMaxGaussStages> lagrange_basis_values(const std::array<double, kMaxGaussStages>& points, int count,
                                                          double tau) {
  std::array<double, kMaxGaussStages> values{};
  for (int j = 0; j < count; ++j) values[j] = lagrange_basis<double, double>(points, count, j, tau);
  return values;
}

std::array<double, kMaxGaussStages> lagrange_basis_integrals(const std::array<double, kMaxGaussStages>& points,
                                                             int count, double from, double to) {
  std::array<double, kMaxGaussStages> integrals{};
  for (int j = 0; j < count; ++j) {
    integrals[j] = static_cast<double>(integrate_basis(points, count, j, from, to));
  }
  return integrals;
}

}  // namespace birkhoff_cart
