// A Birkhoffian system whose functions are Python callables on numpy arrays: a model of the system
// concept (birkhoffian_system.h) for z of Dimension components and no passive coordinates, for
// simulator.integrate (docs/python.md, "Your own Birkhoffian system").
//
// The user gives ∇B(z, t) and optionally K(z, t) (default K₀ = [[0, −I], [I, 0]]: canonical
// coordinates z = (q, p)), ∂R/∂t(z, t) and a non-Birkhoffian force Λ(z, t) (default 0), all in the
// convention of docs/birkhoffian.md eq. (B.1): K ż = ∇B + ∂R/∂t + Λ. Without a chart of their own the
// members step in z itself (the identity chart, ẇ = ż = K⁻¹(∇B + ∂R/∂t + Λ), K LU-factored at every
// call): K-symplectic where K is constant. With a Darboux chart (to_darboux, from_darboux and
// darboux_rates, all three) they step in it, K(z,t)-symplectic where Λ = 0, as a C++ system does.
// The Jacobian ∂ẇ/∂w of the stage solve is the user's `jacobian(w, t)` when given, else central
// differences of ẇ (2·Dimension evaluations).
//
// Every call holds the GIL (the integration runs with it held); a callable's exception passes
// through the integrators to the caller; a result of the wrong shape is a ValueError naming the
// function. Each call converts z to a fresh numpy array and back: the price of a callback is
// measured in bench/python_system_price.py.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <Eigen/Core>
#include <Eigen/LU>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

#include "birkhoff_cart/core/integrators/birkhoffian_system.h"

namespace birkhoff_cart {
namespace python {

namespace py = pybind11;

/// The callables of a user's system (None where not given).
struct SystemFunctions {
  py::object birkhoffian_gradient;                // ∇B(z, t) [J / z units]
  py::object structure_matrix;                    // K(z, t), or None: K₀
  py::object birkhoff_functions_time_derivative;  // ∂R/∂t(z, t), or None: 0
  py::object non_birkhoffian_force;               // Λ(z, t), or None: 0
  py::object to_darboux;                          // w = D(z, t), or None: the identity chart
  py::object from_darboux;                        // z = D⁻¹(w, t)
  py::object darboux_rates;                       // ẇ(w, t)
  py::object jacobian;                            // ∂ẇ/∂w (w, t), or None: central differences
  std::uint64_t* jacobian_evaluations = nullptr;  // counts the Jacobians formed (user or differences)
};

template <int Dimension>
Eigen::Matrix<double, Dimension, 1> call_vector(const py::object& function, const char* name,
                                                const Eigen::Matrix<double, Dimension, 1>& x, double t) {
  py::array_t<double> argument(Dimension);
  for (int i = 0; i < Dimension; ++i) argument.mutable_at(i) = x(i);
  const py::object returned = function(argument, t);
  const auto values = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(returned);
  if (!values || values.ndim() != 1 || values.shape(0) != Dimension) {
    throw py::value_error(std::string(name) + " must return a sequence of " + std::to_string(Dimension) +
                          " numbers, got " + py::repr(returned).cast<std::string>());
  }
  Eigen::Matrix<double, Dimension, 1> result;
  for (int i = 0; i < Dimension; ++i) result(i) = values.at(i);
  return result;
}

template <int Dimension>
Eigen::Matrix<double, Dimension, Dimension> call_matrix(const py::object& function, const char* name,
                                                        const Eigen::Matrix<double, Dimension, 1>& x, double t) {
  py::array_t<double> argument(Dimension);
  for (int i = 0; i < Dimension; ++i) argument.mutable_at(i) = x(i);
  const py::object returned = function(argument, t);
  const auto values = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(returned);
  if (!values || values.ndim() != 2 || values.shape(0) != Dimension || values.shape(1) != Dimension) {
    throw py::value_error(std::string(name) + " must return a " + std::to_string(Dimension) + " x " +
                          std::to_string(Dimension) + " array, got " + py::repr(returned).cast<std::string>());
  }
  Eigen::Matrix<double, Dimension, Dimension> result;
  for (int i = 0; i < Dimension; ++i) {
    for (int j = 0; j < Dimension; ++j) result(i, j) = values.at(i, j);
  }
  return result;
}

/// The user's system in the identity chart (IdentityChart = true) or in its own chart.
template <int Dimension, bool IdentityChart>
class PythonBirkhoffianSystem {
 public:
  static constexpr int kDimension = Dimension;
  static constexpr int kPassiveDimension = 0;
  /// The identity chart is linear, so the members carry compensated-summation remainders through it.
  static constexpr bool kDarbouxChartIsIdentity = IdentityChart;
  static constexpr bool kDarbouxChartIsLinear = IdentityChart;
  template <class S>
  using Vector = Eigen::Matrix<S, Dimension, 1>;
  template <class S>
  using Matrix = Eigen::Matrix<S, Dimension, Dimension>;

  explicit PythonBirkhoffianSystem(const SystemFunctions& functions) : f_(functions) {}

  bool non_birkhoffian_force_enabled() const { return !f_.non_birkhoffian_force.is_none(); }

  /// ẇ(w, t): the user's darboux_rates, or ż = K⁻¹(∇B + ∂R/∂t + Λ) in the identity chart (eq. (B.1)).
  Vector<double> darboux_rates(const Vector<double>& w, double t) const {
    if constexpr (!IdentityChart) {
      return call_vector<Dimension>(f_.darboux_rates, "darboux_rates", w, t);
    } else {
      Vector<double> right_hand_side = call_vector<Dimension>(f_.birkhoffian_gradient, "birkhoffian_gradient", w, t);
      if (!f_.birkhoff_functions_time_derivative.is_none()) {
        right_hand_side += call_vector<Dimension>(f_.birkhoff_functions_time_derivative,
                                                  "birkhoff_functions_time_derivative", w, t);
      }
      if (!f_.non_birkhoffian_force.is_none()) {
        right_hand_side += call_vector<Dimension>(f_.non_birkhoffian_force, "non_birkhoffian_force", w, t);
      }
      if (f_.structure_matrix.is_none()) return -canonical_structure<Dimension>() * right_hand_side;  // K₀⁻¹ = −K₀
      const Matrix<double> k = call_matrix<Dimension>(f_.structure_matrix, "structure_matrix", w, t);
      const Eigen::FullPivLU<Matrix<double>> lu(k);
      if (!lu.isInvertible()) return Vector<double>::Constant(std::numeric_limits<double>::quiet_NaN());
      return lu.solve(right_hand_side);
    }
  }

  /// J = ∂ẇ/∂w at (w, t): the user's, or central differences with steps √ε·max(1, |wᵢ|).
  Matrix<double> darboux_jacobian(const Vector<double>& w, double t) const {
    if (f_.jacobian_evaluations != nullptr) ++*f_.jacobian_evaluations;
    if (!f_.jacobian.is_none()) return call_matrix<Dimension>(f_.jacobian, "jacobian", w, t);
    Matrix<double> jacobian;
    const double root_epsilon = std::sqrt(std::numeric_limits<double>::epsilon());
    for (int j = 0; j < Dimension; ++j) {
      const double step = root_epsilon * std::max(1.0, std::abs(w(j)));
      Vector<double> ahead = w;
      Vector<double> behind = w;
      ahead(j) += step;
      behind(j) -= step;
      jacobian.col(j) = (darboux_rates(ahead, t) - darboux_rates(behind, t)) / (ahead(j) - behind(j));
    }
    return jacobian;
  }

  Vector<double> to_darboux(const Vector<double>& z, double t) const {
    if constexpr (IdentityChart) {
      static_cast<void>(t);
      return z;
    } else {
      return call_vector<Dimension>(f_.to_darboux, "to_darboux", z, t);
    }
  }
  Vector<double> from_darboux(const Vector<double>& w, double t) const {
    if constexpr (IdentityChart) {
      static_cast<void>(t);
      return w;
    } else {
      return call_vector<Dimension>(f_.from_darboux, "from_darboux", w, t);
    }
  }

  /// No passive coordinates.
  template <class S>
  Eigen::Matrix<S, 0, 1> passive_rates(const Vector<S>& /*z*/, const S& /*t*/) const {
    return {};
  }

 private:
  SystemFunctions f_;
};

}  // namespace python
}  // namespace birkhoff_cart
