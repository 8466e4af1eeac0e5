// Dense output of a step grid (docs/birkhoffian.md §12.3, eq. (B.52)): the state at any instant
// inside the grid's last step, from the last m grid points (tⱼ, xⱼ) and their rates ẋⱼ = f(xⱼ, tⱼ)
// by Hermite interpolation — the polynomial P of degree 2m − 1 with P(tⱼ) = xⱼ, P'(tⱼ) = ẋⱼ:
//
//   x(t) − P(t) = x^{(2m)}(ξ)/(2m)! · Πⱼ (t − tⱼ)²,   i.e. O(h^{2m}) inside the last step.
//
// With m = max(2, p/2) points for a member of order p, the interpolant's error is of the method's
// own order (cubic for p ≤ 4, quintic for p = 6, septic for p = 8): an output between grid points
// is as accurate as the grid, where the collocation polynomial of an s-stage Gauss step is only
// O(h^{s+1}) inside the step. The grid points are the accepted steps' own states (O(h^p) accurate);
// the rates cost one evaluation per point, made only when an output falls inside a step. After a
// restart (the start, a kink, a new command) fewer points are at hand and the degree is lower until
// the grid has taken m − 1 steps.
//
// Newton's divided differences on the doubled abscissae (confluent: f[tⱼ, tⱼ] = ẋⱼ), evaluated with
// the time measured from the last grid point so that long runs lose no digits in t.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace birkhoff_cart {

/// Hermite dense output of a vector of `Size` components over the last `MaxPoints` grid points.
template <int Size, int MaxPoints = 5>
class HermiteDenseOutput {
 public:
  using Vector = Eigen::Matrix<double, Size, 1>;

  /// `points`: how many grid points the interpolant uses, 1 … MaxPoints (degree 2·points − 1).
  explicit HermiteDenseOutput(int points = 2) : points_(points) {
    if (points < 1 || points > MaxPoints) throw std::invalid_argument("Hermite dense output: too many points");
  }

  /// Forget every point (a restart of the grid).
  void clear() { count_ = 0; }
  /// Grid points held [-].
  int size() const { return count_; }
  /// Time of the newest point [s] (requires size() > 0).
  double newest_time() const { return times_[0]; }
  /// Time of the oldest point the interpolant uses [s].
  double oldest_time() const { return times_[count_ - 1]; }

  /// Adds a grid point (t [s], x) after the newest one, its rate not yet known; the oldest beyond
  /// `points` is dropped.
  void push(double t, const Vector& value) {
    const int kept = count_ < points_ ? count_ : points_ - 1;
    for (int j = kept; j > 0; --j) {
      times_[j] = times_[j - 1];
      values_[j] = values_[j - 1];
      rates_[j] = rates_[j - 1];
      has_rate_[j] = has_rate_[j - 1];
    }
    times_[0] = t;
    values_[0] = value;
    has_rate_[0] = false;
    count_ = kept + 1;
  }
  /// Adds a grid point with its rate ẋ = f(x, t).
  void push(double t, const Vector& value, const Vector& rate) {
    push(t, value);
    set_rate(0, rate);
  }

  /// Point j (0: newest): its time [s], value, and whether its rate is known. Rates are needed only
  /// when an output falls inside the grid's last step, so callers fill them then (set_rate).
  double time(int j) const { return times_[j]; }
  const Vector& value(int j) const { return values_[j]; }
  bool has_rate(int j) const { return has_rate_[j]; }
  void set_rate(int j, const Vector& rate) {
    rates_[j] = rate;
    has_rate_[j] = true;
  }
  /// Adds `delta` to component k of every value held (an angle whose whole turns were taken out:
  /// the points then stay on one branch).
  void shift_component(int k, double delta) {
    for (int j = 0; j < count_; ++j) values_[j](k) += delta;
  }

  /// x(t) for t in [oldest_time(), newest_time()] (meant for the newest step); needs ≥ 1 point, each
  /// with its rate. Exactly the newest point's value at its time. With `difference`, also the
  /// interpolant through every point but the oldest, subtracted from it: an estimate of the error of
  /// the lower-degree one, so a conservative one of this (NaN, unknown, with a single point).
  Vector at(double t, Vector* difference = nullptr) const {
    if (count_ == 0) throw std::logic_error("Hermite dense output: no grid point yet");
    if (difference != nullptr) difference->setZero();
    if (t == times_[0]) return values_[0];
    for (int j = 0; j < count_; ++j) {
      if (!has_rate_[j]) throw std::logic_error("Hermite dense output: a grid point without its rate");
    }
    // Abscissae (doubled), newest first, so that dropping the oldest point drops the last two terms
    // of the Newton form; τ = t − t_newest keeps full precision in long runs.
    constexpr int kMaxNodes = 2 * MaxPoints;
    std::array<double, kMaxNodes> node{};
    std::array<Vector, kMaxNodes> table;
    table.fill(Vector::Zero());
    const int nodes = 2 * count_;
    for (int j = 0; j < count_; ++j) {
      const double tau = times_[j] - times_[0];
      node[2 * j] = tau;
      node[2 * j + 1] = tau;
      table[2 * j] = values_[j];
      table[2 * j + 1] = values_[j];
    }
    // Divided differences in place: after column c, table[i] = f[node[i − c] … node[i]].
    std::array<Vector, kMaxNodes> first;  // first-order column, kept for the confluent entries
    first.fill(Vector::Zero());
    for (int i = nodes - 1; i >= 1; --i) {
      if (node[i] == node[i - 1]) {
        first[i] = rates_[i / 2];  // f[tⱼ, tⱼ] = ẋⱼ
      } else {
        first[i] = (table[i] - table[i - 1]) / (node[i] - node[i - 1]);
      }
    }
    for (int i = 1; i < nodes; ++i) table[i] = first[i];
    for (int order = 2; order < nodes; ++order) {
      for (int i = nodes - 1; i >= order; --i) table[i] = (table[i] - table[i - 1]) / (node[i] - node[i - order]);
    }
    // The Newton form P(τ) = Σ_c table[c] Π_{i<c} (τ − node[i]), term by term.
    const double tau = t - times_[0];
    Vector result = table[0];
    Vector last_two = Vector::Zero();
    double product = 1.0;
    for (int c = 1; c < nodes; ++c) {
      product *= tau - node[c - 1];
      const Vector term = product * table[c];
      result += term;
      if (c >= nodes - 2 && count_ > 1) last_two += term;
    }
    if (difference != nullptr) {
      *difference = count_ > 1 ? last_two : Vector::Constant(std::numeric_limits<double>::quiet_NaN());
    }
    return result;
  }

 private:
  int points_;
  int count_ = 0;
  std::array<double, MaxPoints> times_{};   ///< newest first [s]
  std::array<Vector, MaxPoints> values_;    ///< newest first
  std::array<Vector, MaxPoints> rates_;     ///< newest first
  std::array<bool, MaxPoints> has_rate_{};
};

}  // namespace birkhoff_cart
