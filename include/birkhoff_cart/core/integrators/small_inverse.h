// The inverse of a small fixed-size matrix (the collocation members' Newton matrices I − h A ⊗ J,
// 4 to 16 rows) by Gauss–Jordan elimination with partial pivoting, in plain loops over row-major
// storage that the compiler unrolls. Eigen's partialPivLu().inverse() goes through its blocked LU,
// packing and triangular-solve kernels, built for large matrices: on the 12-row matrix of
// birkhoff_gauss6 they took ~30 % of a step's time on the whirl (perf, docs/benchmarks.md).
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <utility>

namespace birkhoff_cart {

/// `inverse` = `matrix`⁻¹; false (and `inverse` unspecified) when a pivot is zero or the result is
/// not finite. Partial pivoting: the largest |entry| of the column at or below the diagonal.
template <int N>
bool invert_small_matrix(const Eigen::Matrix<double, N, N>& matrix, Eigen::Matrix<double, N, N>& inverse) {
  using RowMajor = Eigen::Matrix<double, N, N, Eigen::RowMajor>;
  RowMajor left = matrix;                            // reduced to I
  RowMajor right = RowMajor::Identity();             // becomes matrix⁻¹
  for (int column = 0; column < N; ++column) {
    int pivot = column;
    double largest = std::abs(left(column, column));
    for (int row = column + 1; row < N; ++row) {
      const double size = std::abs(left(row, column));
      if (size > largest) {
        largest = size;
        pivot = row;
      }
    }
    if (!(largest > 0.0)) return false;
    if (pivot != column) {
      left.row(column).swap(left.row(pivot));
      right.row(column).swap(right.row(pivot));
    }
    const double reciprocal = 1.0 / left(column, column);
    for (int k = column; k < N; ++k) left(column, k) *= reciprocal;
    for (int k = 0; k < N; ++k) right(column, k) *= reciprocal;
    for (int row = 0; row < N; ++row) {
      if (row == column) continue;
      const double factor = left(row, column);
      if (factor == 0.0) continue;
      for (int k = column; k < N; ++k) left(row, k) -= factor * left(column, k);
      for (int k = 0; k < N; ++k) right(row, k) -= factor * right(column, k);
    }
  }
  inverse = right;
  return inverse.allFinite();
}

}  // namespace birkhoff_cart
