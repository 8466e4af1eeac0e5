// The simplified-Newton matrix of s-stage collocation, M = I − X ⊗ J with X = hA (s × s, the
// Butcher matrix times the step) and J = ∂ẇ/∂w (n × n), inverted through its Kronecker structure
// and applied in factored form (docs/birkhoffian.md §10.6, eqs. (B.38)–(B.39)).
//
// Cyclic coordinates. No rate reads a cyclic coordinate (System::kCyclicMask: the cart's arc length
// π1), so J's columns for them are zero and M is block-triangular, [[M_aa, 0], [M_ca, I]] in
// (a: the m other coordinates, c: the cyclic ones) of every stage:
//   M⁻¹ = [[M_aa⁻¹, 0], [−M_ca M_aa⁻¹, I]],   −M_ca = X ⊗ J_ca.
// (Where a cyclic column is not zero after all, every coordinate is in a, m = n.)
//
// The block M_aa = I − X ⊗ J_aa. For one eigenvalue μ of X, Cayley–Hamilton on the m × m J_aa gives
//   (I − μJ)⁻¹ = Σ_{p<m} f_p(μ) J^p,   f_p = N_p / D,
//   D(μ) = det(I − μJ) = Σ_{k≤m} (−1)^k e_k μ^k,   N_p(μ) = Σ_{p≤j<m} (−1)^{j−p} e_{j−p} μ^j,   (B.38)
// e_k the coefficients of J's characteristic polynomial (Faddeev–LeVerrier). The f_p are rational
// functions, so with μ → X (all of them commute with X):
//   M_aa⁻¹ = Σ_p f_p(X) ⊗ J^p,   f_p(X) = N_p(X) D(X)⁻¹,                                      (B.39)
// one s × s inverse. Building costs ~m⁴ + m s³ operations, against (sm)³ for elimination on the
// s·m rows, so the matrix can be renewed every step (J at the step's own stages: fewer iterations).
// Applying it, ΔZ = M⁻¹ G costs m²s² + m³s operations, about what the assembled (sn)² product
// would.
#pragma once

#include <Eigen/Core>
#include <Eigen/LU>
#include <array>
#include <cmath>
#include <type_traits>
#include <utility>


namespace birkhoff_cart {

template <int n, int s>
class KroneckerNewtonInverse {
 public:
  using Jacobian = Eigen::Matrix<double, n, n>;

  /// Builds M⁻¹ for J, X = h·coefficients, taking the coordinates in `cyclic_mask` out of the block
  /// where their J columns are zero. false when M is singular or a factor not finite.
  template <class Coefficients>
  bool build(const Jacobian& jacobian, const Coefficients& coefficients, double h, unsigned cyclic_mask) {
    bool reduce = false;
    for (int c = 0; c < n; ++c) {
      if (!(cyclic_mask & (1u << c))) continue;
      reduce = true;
      for (int r = 0; r < n; ++r) reduce = reduce && jacobian(r, c) == 0.0;
      if (!reduce) break;
    }
    m_ = 0;
    cyclic_count_ = 0;
    for (int k = 0; k < n; ++k) {
      if (reduce && (cyclic_mask & (1u << k))) {
        cyclic_[cyclic_count_++] = k;
      } else {
        active_[m_++] = k;
      }
    }
    return with_block_size(m_, [&](auto block) {
      return build_block<decltype(block)::value>(jacobian, coefficients, h);
    });
  }

  /// correction = M⁻¹ residual, both s blocks of n (stage by stage). Any scalar S (AD jets too).
  template <class S>
  void apply(const std::array<S, n * s>& residual, std::array<S, n * s>& correction) const {
    with_block_size(m_, [&](auto block) {
      apply_block<decltype(block)::value>(residual, correction);
      return true;
    });
  }

  /// The coordinates in the block (n, or n minus the cyclic ones) [-].
  int block_size() const { return m_; }

 private:
  using Small = std::array<std::array<double, n>, n>;
  using Square = std::array<std::array<double, s>, s>;

  /// product = left · right on the leading size × size entries.
  template <class Matrix>
  static void multiply(const Matrix& left, const Matrix& right, Matrix& product, int size) {
    for (int i = 0; i < size; ++i) {
      for (int j = 0; j < size; ++j) {
        double sum = 0.0;
        for (int k = 0; k < size; ++k) sum += left[i][k] * right[k][j];
        product[i][j] = sum;
      }
    }
  }

  /// build() on a block of m coordinates (m a constant: the loops unroll).
  template <int m, class Coefficients>
  bool build_block(const Jacobian& jacobian, const Coefficients& coefficients, double h) {
    Small j_aa{};
    for (int a = 0; a < m; ++a) {
      for (int b = 0; b < m; ++b) j_aa[a][b] = jacobian(active_[a], active_[b]);
    }
    for (int p = 0; p < n; ++p) j_power_[p] = Small{};
    for (int a = 0; a < m; ++a) j_power_[0][a][a] = 1.0;
    for (int p = 1; p < m; ++p) multiply(j_aa, j_power_[p - 1], j_power_[p], m);
    // e_k: det(xI − J) = Σ_k (−1)^k e_k x^{m−k} = Σ_k c_{m−k} x^{m−k}, e_k = (−1)^k c_{m−k}.
    // Faddeev–LeVerrier: B₁ = I, c_{m−k} = −tr(J B_k)/k, B_{k+1} = J B_k + c_{m−k} I.
    std::array<double, n + 1> e{};
    e[0] = 1.0;
    Small b_k = j_power_[0];
    for (int k = 1; k <= m; ++k) {
      Small jb{};
      multiply(j_aa, b_k, jb, m);
      double trace = 0.0;
      for (int a = 0; a < m; ++a) trace += jb[a][a];
      const double c = -trace / k;
      e[k] = (k % 2 == 0) ? c : -c;
      for (int a = 0; a < m; ++a) jb[a][a] += c;
      b_k = jb;
    }
    // y_j = X^j D(X)⁻¹, j ≤ m: f_p = Σ_{p≤j<m} (−1)^{j−p} e_{j−p} y_j and X f_p the same on y_{j+1}.
    std::array<Square, n + 1> x_power{};
    for (int i = 0; i < s; ++i) {
      x_power[0][i][i] = 1.0;
      for (int j = 0; j < s; ++j) x_power[1][i][j] = h * coefficients[i][j];
    }
    for (int k = 2; k <= m; ++k) multiply(x_power[1], x_power[k - 1], x_power[k], s);
    Eigen::Matrix<double, s, s> denominator = Eigen::Matrix<double, s, s>::Zero();  // D(X)
    for (int k = 0; k <= m; ++k) {
      const double coefficient = (k % 2 == 0) ? e[k] : -e[k];
      for (int i = 0; i < s; ++i) {
        for (int j = 0; j < s; ++j) denominator(i, j) += coefficient * x_power[k][i][j];
      }
    }
    // Eigen's closed-form inverse for s ≤ 4; a singular D gives non-finite entries (checked below).
    const Eigen::Matrix<double, s, s> denominator_inverse = denominator.inverse();
    if (!denominator_inverse.allFinite()) return false;
    std::array<Square, n + 1> y{};
    for (int k = 0; k <= m; ++k) {
      for (int i = 0; i < s; ++i) {
        for (int j = 0; j < s; ++j) {
          double sum = 0.0;
          for (int q = 0; q < s; ++q) sum += x_power[k][i][q] * denominator_inverse(q, j);
          y[k][i][j] = sum;
        }
      }
    }
    for (int p = 0; p < m; ++p) {
      f_[p] = Square{};
      x_f_[p] = Square{};
      for (int j = p; j < m; ++j) {
        const double coefficient = ((j - p) % 2 == 0) ? e[j - p] : -e[j - p];
        for (int r = 0; r < s; ++r) {
          for (int q = 0; q < s; ++q) {
            f_[p][r][q] += coefficient * y[j][r][q];
            x_f_[p][r][q] += coefficient * y[j + 1][r][q];
          }
        }
      }
    }
    // The cyclic rows: J_ca J^p.
    for (int c = 0; c < cyclic_count_; ++c) {
      for (int p = 0; p < m; ++p) {
        for (int b = 0; b < m; ++b) {
          double sum = 0.0;
          for (int a = 0; a < m; ++a) sum += jacobian(cyclic_[c], active_[a]) * j_power_[p][a][b];
          row_power_[c][p][b] = sum;
        }
      }
    }
    return all_finite();
  }

  template <int m, class S>
  void apply_block(const std::array<S, n * s>& residual, std::array<S, n * s>& correction) const {
    const S zero = S(0.0) * residual[0];
    // H_p(a, i) = Σ_j f_p(i, j) G_j(a)
    std::array<std::array<std::array<S, s>, n>, n> h_p;
    for (int p = 0; p < m; ++p) {
      for (int a = 0; a < m; ++a) {
        for (int i = 0; i < s; ++i) {
          S sum = zero;
          for (int j = 0; j < s; ++j) sum += f_[p][i][j] * residual[j * n + active_[a]];
          h_p[p][a][i] = sum;
        }
      }
    }
    // ΔZ_i(a) = Σ_p Σ_b (J^p)(a, b) H_p(b, i)
    for (int i = 0; i < s; ++i) {
      for (int a = 0; a < m; ++a) {
        S sum = h_p[0][a][i];
        for (int p = 1; p < m; ++p) {
          for (int b = 0; b < m; ++b) sum += j_power_[p][a][b] * h_p[p][b][i];
        }
        correction[i * n + active_[a]] = sum;
      }
    }
    // ΔZ_i(c) = G_i(c) + Σ_p Σ_j (X f_p)(i, j) (J_ca J^p · G_j)
    for (int c = 0; c < cyclic_count_; ++c) {
      std::array<std::array<S, s>, n> q;
      for (int p = 0; p < m; ++p) {
        for (int j = 0; j < s; ++j) {
          S sum = zero;
          for (int a = 0; a < m; ++a) sum += row_power_[c][p][a] * residual[j * n + active_[a]];
          q[p][j] = sum;
        }
      }
      for (int i = 0; i < s; ++i) {
        S sum = residual[i * n + cyclic_[c]];
        for (int p = 0; p < m; ++p) {
          for (int j = 0; j < s; ++j) sum += x_f_[p][i][j] * q[p][j];
        }
        correction[i * n + cyclic_[c]] = sum;
      }
    }
  }

  /// f(std::integral_constant<int, size>) for the block size in use, so that the loops over the
  /// block have constant bounds; false when no block size ≤ m matches (none: m_ ≥ 1 always).
  template <int m = n, class F>
  static bool with_block_size(int size, F&& f) {
    if constexpr (m >= 1) {
      if (size == m) return f(std::integral_constant<int, m>{});
      return with_block_size<m - 1>(size, std::forward<F>(f));
    } else {
      return false;
    }
  }

  bool all_finite() const {
    for (int p = 0; p < m_; ++p) {
      for (int i = 0; i < s; ++i) {
        for (int j = 0; j < s; ++j) {
          if (!std::isfinite(f_[p][i][j]) || !std::isfinite(x_f_[p][i][j])) return false;
        }
      }
      for (int a = 0; a < m_; ++a) {
        for (int b = 0; b < m_; ++b) {
          if (!std::isfinite(j_power_[p][a][b])) return false;
        }
      }
    }
    return true;
  }

  // The factors are left uninitialised until build() writes them: nothing reads beyond m_ and
  // cyclic_count_, and a CollocationMemory holds kCachedStepSizes of these (18 KB for the 4-stage
  // member on the cart), which zeroing cost 7 % of a short controlled run (drive_rr_drag at 1e-2 m:
  // 57 000 of 824 000 instructions, for six memories; bench/price_callgrind.py).
  int m_ = 0;                                 ///< coordinates in the block
  int cyclic_count_ = 0;                      ///< cyclic coordinates taken out of it
  std::array<int, n> active_{};               ///< the block's coordinates
  std::array<int, n> cyclic_{};               ///< the cyclic ones
  std::array<Square, n> f_;                   ///< f_p(X), p < m
  std::array<Square, n> x_f_;                 ///< X f_p(X)
  std::array<Small, n> j_power_;              ///< J^p on the block, p < m
  std::array<std::array<std::array<double, n>, n>, n> row_power_;  ///< [cyclic][p]: J_ca J^p, p < m
};

}  // namespace birkhoff_cart
