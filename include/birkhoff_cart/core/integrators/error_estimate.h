// The weighted norm every integrator uses for its local error estimate ê (diagnostics.h,
// StepStatistics; docs/accuracy.md §1, (A.1)). An integrator that has an error vector e = x̂ − x for a
// step (the difference between its solution and an embedded one, a defect, ...) reports it as
//
//   record_local_error_estimate(statistics, local_error_norm(z_start, y_start, z_error, y_error));
//
// once per step. The weights make ê dimensionless: the Birkhoffian coordinates z absolutely below 1 SI
// unit and relatively above (odeint's error norm with ε_abs = ε_rel = 1, without its h·|ẋ| term); the
// passive coordinates y absolutely, whatever their size:
//
//   ê = max( maxᵢ |e_zᵢ| / max(1, |zᵢ(tₖ)|),  maxⱼ |e_yⱼ| ).                                   (A.1)
//
// The passive coordinates are what the rates carry along (the cart's x, y, heading, wheel angles, and
// the loads' work W and impulse I2): their rates do not depend on them, so neither does a step's error
// in them. A relative measure lets the step errors of those that grow through a run grow with them
// (W above all: thousands of joules on a drive); so measured, dopri5 under the adaptive control ends
// 9–10× its tolerance on very_stiff_hinge and birkhoff_gauss8 up to 9.8× on stiff_hinge
// (docs/accuracy.md §1).
//
// Generic in the scalar S (double or an AD jet): only the values are used.
#pragma once

#include <algorithm>
#include <cmath>

#include "birkhoff_cart/core/integrators/autodiff.h"
#include "birkhoff_cart/core/integrators/birkhoffian_system.h"

namespace birkhoff_cart {

/// max_i |error_i| / max(1, |start_i|) over one vector (Eigen column of double or AD jets) [-].
template <class StartVector, class ErrorVector>
double weighted_max_norm(const StartVector& start, const ErrorVector& error) {
  double norm = 0.0;
  for (int i = 0; i < start.size(); ++i) {
    const double weight = 1.0 / std::max(1.0, std::abs(value_of(start(i))));
    const double component = std::abs(value_of(error(i))) * weight;
    if (std::isnan(component)) return component;
    norm = std::max(norm, component);
  }
  return norm;
}

/// max_i |error_i| over one vector (Eigen column of double or AD jets) [its units]; NaN if any is.
template <class ErrorVector>
double absolute_max_norm(const ErrorVector& error) {
  double norm = 0.0;
  for (int i = 0; i < error.size(); ++i) {
    const double component = std::abs(value_of(error(i)));
    if (std::isnan(component)) return component;
    norm = std::max(norm, component);
  }
  return norm;
}

/// ê of (A.1) for a step from (z_start, y_start) with error vectors (z_error, y_error) [-]. y_start
/// does not weigh (the passive coordinates count absolutely); it stays in the signature so that
/// every integrator reports its step the same way.
template <class System, class S>
double local_error_norm(const StateVector<System, S>& z_start, [[maybe_unused]] const PassiveVector<System, S>& y_start,
                        const StateVector<System, S>& z_error, const PassiveVector<System, S>& y_error) {
  const double z_norm = weighted_max_norm(z_start, z_error);
  const double y_norm = absolute_max_norm(y_error);
  if (std::isnan(z_norm) || std::isnan(y_norm)) return std::nan("");
  return std::max(z_norm, y_norm);
}

}  // namespace birkhoff_cart
