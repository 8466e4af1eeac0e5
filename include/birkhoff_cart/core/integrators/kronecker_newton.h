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
#if defined(__x86_64__)
#include <immintrin.h>
#elif defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "birkhoff_cart/core/integrators/vector_math.h"


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
#if defined(__x86_64__)
      if constexpr (std::is_same<S, double>::value && s == 4) {
        if (stage_evaluation() == StageEvaluation::kVector) {  // the CPU has AVX (vector_math.h)
          apply_block_avx<decltype(block)::value>(residual, correction);
          return true;
        }
      }
#endif
#if defined(__SSE2__)
      if constexpr (std::is_same<S, double>::value && s % 2 == 0) {
        apply_block_by_stages<decltype(block)::value>(residual, correction);
        return true;
      }
#endif
      apply_block<decltype(block)::value>(residual, correction);
      return true;
    });
  }

  /// The coordinates in the block (n, or n minus the cyclic ones) [-].
  int block_size() const { return m_; }

 private:
  using Small = std::array<std::array<double, n>, n>;
  using Square = std::array<std::array<double, s>, s>;

  /// product = left · right on the leading size × size entries (size a constant, so that the loops
  /// unroll: with a run-time bound they were the largest part of the build).
  template <int size, class Matrix>
  static void multiply(const Matrix& left, const Matrix& right, Matrix& product) {
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
    // Only the leading m × m entries of the first m powers are written and read (apply, all_finite).
    for (int a = 0; a < m; ++a) {
      for (int b = 0; b < m; ++b) j_power_[0][a][b] = a == b ? 1.0 : 0.0;
    }
    for (int p = 1; p < m; ++p) multiply<m>(j_aa, j_power_[p - 1], j_power_[p]);
    // e_k: det(xI − J) = Σ_k (−1)^k e_k x^{m−k} = Σ_k c_{m−k} x^{m−k}, e_k = (−1)^k c_{m−k}.
    // Faddeev–LeVerrier: B₁ = I, c_{m−k} = −tr(J B_k)/k, B_{k+1} = J B_k + c_{m−k} I.
    std::array<double, n + 1> e{};
    e[0] = 1.0;
    Small b_k = j_power_[0];
    for (int k = 1; k <= m; ++k) {
      Small jb;
      multiply<m>(j_aa, b_k, jb);
      double trace = 0.0;
      for (int a = 0; a < m; ++a) trace += jb[a][a];
      const double c = -trace / k;
      e[k] = (k % 2 == 0) ? c : -c;
      for (int a = 0; a < m; ++a) jb[a][a] += c;
      b_k = jb;
    }
    // y_j = X^j D(X)⁻¹, j ≤ m: f_p = Σ_{p≤j<m} (−1)^{j−p} e_{j−p} y_j and X f_p the same on y_{j+1}.
    std::array<Square, m + 1> x_power;  // X^k, k ≤ m, each written whole below
    for (int i = 0; i < s; ++i) {
      for (int j = 0; j < s; ++j) {
        x_power[0][i][j] = i == j ? 1.0 : 0.0;
        x_power[1][i][j] = h * coefficients[i][j];
      }
    }
    for (int k = 2; k <= m; ++k) multiply<s>(x_power[1], x_power[k - 1], x_power[k]);
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
    std::array<Square, m + 1> y;  // written whole below
    // y_0 = D(X)⁻¹ (+ 0.0: a −0 entry reads +0, as the product with I it stands for would give).
    for (int i = 0; i < s; ++i) {
      for (int j = 0; j < s; ++j) y[0][i][j] = denominator_inverse(i, j) + 0.0;
    }
    for (int k = 1; k <= m; ++k) {
      for (int i = 0; i < s; ++i) {
        for (int j = 0; j < s; ++j) {
          double sum = 0.0;
          for (int q = 0; q < s; ++q) sum += x_power[k][i][q] * denominator_inverse(q, j);
          y[k][i][j] = sum;
        }
      }
    }
    std::array<double, m> signed_e;  // (−1)^k e_k
    for (int k = 0; k < m; ++k) signed_e[k] = (k % 2 == 0) ? e[k] : -e[k];
    for (int p = 0; p < m; ++p) {
      for (int r = 0; r < s; ++r) {
        for (int q = 0; q < s; ++q) {
          double f = 0.0;
          double x_f = 0.0;
          for (int j = p; j < m; ++j) {
            f += signed_e[j - p] * y[j][r][q];
            x_f += signed_e[j - p] * y[j + 1][r][q];
          }
          f_[p][q][r] = f;  // transposed: column q of f_p(X) is f_[p][q]
          x_f_[p][q][r] = x_f;
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
    return all_finite<m>();
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
          for (int j = 0; j < s; ++j) sum += f_[p][j][i] * residual[j * n + active_[a]];
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
          for (int j = 0; j < s; ++j) sum += x_f_[p][j][i] * q[p][j];
        }
        correction[i * n + cyclic_[c]] = sum;
      }
    }
  }

  /// g[a][j] = G_j(a), the block's rows of the residual stage by stage (the lanes paths' input).
  template <int m>
  void block_rows(const std::array<double, n * s>& residual, double (&g)[m][s]) const {
    for (int a = 0; a < m; ++a) {
      for (int j = 0; j < s; ++j) g[a][j] = residual[j * n + active_[a]];
    }
  }

#if defined(__SSE2__)
  /// s doubles, one per stage, in s/2 SSE2 registers (baseline x86-64): one operation computes an
  /// entry for two stages. Only multiplications and additions, each rounded once as the scalar code
  /// rounds it (no fused multiply-add): the same bits on every x86-64 CPU.
  struct StageLanes {
    __m128d pair[s / 2];
    static StageLanes load(const double* values) {
      StageLanes lanes;
      for (int k = 0; k < s / 2; ++k) lanes.pair[k] = _mm_loadu_pd(values + 2 * k);
      return lanes;
    }
    static StageLanes filled(double value) {
      StageLanes lanes;
      for (int k = 0; k < s / 2; ++k) lanes.pair[k] = _mm_set1_pd(value);
      return lanes;
    }
    void store(double* values) const {
      for (int k = 0; k < s / 2; ++k) _mm_storeu_pd(values + 2 * k, pair[k]);
    }
    /// this += factor · lanes, lane by lane (the product first, as `sum += a * b`).
    void add_product(const StageLanes& lanes, double factor) {
      const __m128d broadcast = _mm_set1_pd(factor);
      for (int k = 0; k < s / 2; ++k) pair[k] = _mm_add_pd(pair[k], _mm_mul_pd(lanes.pair[k], broadcast));
    }
  };

  /// apply_block() for doubles with the stages in the lanes of SSE2 registers: every entry adds its
  /// terms in the order apply_block() does (the same sums, the same bits), two stages per
  /// instruction. For gauss8 (s = 4) the scalar apply was 24 % of a fixed-step run on
  /// sine_steer_torque, ~800 instructions for its ~300 multiply-adds (bench/price_callgrind.py); the
  /// compiler did not vectorise its loops, nor the same loops written with the stages innermost.
  template <int m>
  void apply_block_by_stages(const std::array<double, n * s>& residual, std::array<double, n * s>& correction) const {
    const double zero = 0.0 * residual[0];  // apply_block()'s start of every sum (−0 where it is)
    double g[m][s];
    block_rows<m>(residual, g);
    // H_p(a, ·) = Σ_j f_p(·, j) G_j(a)
    StageLanes h_p[m][m];
    for (int p = 0; p < m; ++p) {
      StageLanes columns[s];
      for (int j = 0; j < s; ++j) columns[j] = StageLanes::load(f_[p][j].data());
      for (int a = 0; a < m; ++a) {
        StageLanes sum = StageLanes::filled(zero);
        for (int j = 0; j < s; ++j) sum.add_product(columns[j], g[a][j]);
        h_p[p][a] = sum;
      }
    }
    // ΔZ_·(a) = Σ_p Σ_b (J^p)(a, b) H_p(b, ·)
    for (int a = 0; a < m; ++a) {
      StageLanes sum = h_p[0][a];
      for (int p = 1; p < m; ++p) {
        for (int b = 0; b < m; ++b) sum.add_product(h_p[p][b], j_power_[p][a][b]);
      }
      double stages[s];
      sum.store(stages);
      for (int i = 0; i < s; ++i) correction[i * n + active_[a]] = stages[i];
    }
    // ΔZ_·(c) = G_·(c) + Σ_p Σ_j (X f_p)(·, j) (J_ca J^p · G_j)
    for (int c = 0; c < cyclic_count_; ++c) {
      double stages[s];
      for (int i = 0; i < s; ++i) stages[i] = residual[i * n + cyclic_[c]];
      StageLanes sum = StageLanes::load(stages);
      for (int p = 0; p < m; ++p) {
        StageLanes q = StageLanes::filled(zero);  // lane j: J_ca J^p · G_j
        for (int a = 0; a < m; ++a) q.add_product(StageLanes::load(g[a]), row_power_[c][p][a]);
        double q_j[s];
        q.store(q_j);
        for (int j = 0; j < s; ++j) sum.add_product(StageLanes::load(x_f_[p][j].data()), q_j[j]);
      }
      sum.store(stages);
      for (int i = 0; i < s; ++i) correction[i * n + cyclic_[c]] = stages[i];
    }
  }
#endif

#if defined(__x86_64__)
  /// apply_block_by_stages() for four stages in one AVX register (the vector stage evaluation of
  /// vector_math.h: chosen at run time where the CPU has AVX). The same multiplications and additions
  /// in the same order, without fused multiply-add, so the bits are the scalar loops' again; the
  /// three-operand AVX forms also spare the register copies that SSE2's two-operand forms need
  /// (gauss8 on the cart: about 380 instructions an apply against the pairs' 750; birkhoffian.md
  /// §10.6).
  template <int m>
  __attribute__((target("avx"))) void apply_block_avx(const std::array<double, n * s>& residual,
                                                      std::array<double, n * s>& correction) const {
    static_assert(s == 4, "one AVX register holds the four stages");
    const __m256d zeros = _mm256_set1_pd(0.0 * residual[0]);  // apply_block()'s start of every sum
    double g[m][s];
    block_rows<m>(residual, g);
    // H_p(a, ·) = Σ_j f_p(·, j) G_j(a)
    __m256d h_p[m][m];
    for (int p = 0; p < m; ++p) {
      __m256d columns[s];
      for (int j = 0; j < s; ++j) columns[j] = _mm256_loadu_pd(f_[p][j].data());
      for (int a = 0; a < m; ++a) {
        __m256d sum = zeros;
        for (int j = 0; j < s; ++j) sum = _mm256_add_pd(sum, _mm256_mul_pd(columns[j], _mm256_set1_pd(g[a][j])));
        h_p[p][a] = sum;
      }
    }
    // ΔZ_·(a) = Σ_p Σ_b (J^p)(a, b) H_p(b, ·)
    for (int a = 0; a < m; ++a) {
      __m256d sum = h_p[0][a];
      for (int p = 1; p < m; ++p) {
        for (int b = 0; b < m; ++b) sum = _mm256_add_pd(sum, _mm256_mul_pd(h_p[p][b], _mm256_set1_pd(j_power_[p][a][b])));
      }
      double stages[s];
      _mm256_storeu_pd(stages, sum);
      for (int i = 0; i < s; ++i) correction[i * n + active_[a]] = stages[i];
    }
    // ΔZ_·(c) = G_·(c) + Σ_p Σ_j (X f_p)(·, j) (J_ca J^p · G_j)
    for (int c = 0; c < cyclic_count_; ++c) {
      double stages[s];
      for (int i = 0; i < s; ++i) stages[i] = residual[i * n + cyclic_[c]];
      __m256d sum = _mm256_loadu_pd(stages);
      for (int p = 0; p < m; ++p) {
        __m256d q = zeros;  // lane j: J_ca J^p · G_j
        for (int a = 0; a < m; ++a) q = _mm256_add_pd(q, _mm256_mul_pd(_mm256_loadu_pd(g[a]), _mm256_set1_pd(row_power_[c][p][a])));
        double q_j[s];
        _mm256_storeu_pd(q_j, q);
        for (int j = 0; j < s; ++j) sum = _mm256_add_pd(sum, _mm256_mul_pd(_mm256_loadu_pd(x_f_[p][j].data()), _mm256_set1_pd(q_j[j])));
      }
      _mm256_storeu_pd(stages, sum);
      for (int i = 0; i < s; ++i) correction[i * n + cyclic_[c]] = stages[i];
    }
  }
#endif

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

  /// Every factor finite (one product per factor: a non-finite entry makes it NaN, and the loop has
  /// no early exit to branch on).
  template <int m>
  bool all_finite() const {
    double product = 0.0;
    for (int p = 0; p < m; ++p) {
      for (int i = 0; i < s; ++i) {
        for (int j = 0; j < s; ++j) product += 0.0 * f_[p][i][j] + 0.0 * x_f_[p][i][j];
      }
      for (int a = 0; a < m; ++a) {
        for (int b = 0; b < m; ++b) product += 0.0 * j_power_[p][a][b];
      }
    }
    return product == 0.0;
  }

  // The factors are left uninitialised until build() writes them: nothing reads beyond m_ and
  // cyclic_count_, and a CollocationMemory holds kCachedStepSizes of these (18 KB for the 4-stage
  // member on the cart), which zeroing cost 7 % of a short controlled run (drive_rr_drag at 1e-2 m:
  // 57 000 of 824 000 instructions, for six memories; bench/price_callgrind.py).
  int m_ = 0;                                 ///< coordinates in the block
  int cyclic_count_ = 0;                      ///< cyclic coordinates taken out of it
  std::array<int, n> active_{};               ///< the block's coordinates
  std::array<int, n> cyclic_{};               ///< the cyclic ones
  std::array<Square, n> f_;                   ///< f_p(X), p < m, by columns: f_[p][j][i] = f_p(X)(i, j)
  std::array<Square, n> x_f_;                 ///< X f_p(X), by columns as f_
  std::array<Small, n> j_power_;              ///< J^p on the block, p < m
  std::array<std::array<std::array<double, n>, n>, n> row_power_;  ///< [cyclic][p]: J_ca J^p, p < m
};

}  // namespace birkhoff_cart
