// The paper's eᵗ form is not structure-preserving over long runs (docs/birkhoffian.md §10): a member
// that steps in its Darboux chart w = (π1, χ, e^{t−tₑ} p) multiplies the momenta by a factor
// 1 + δ(h) per step whatever the motion — for birkhoff2 δ = (1 + h/2)/(1 − h/2)·e^{−h} − 1
// = h³/12 + O(h⁵) — so they grow like (1 + δ)^{t/h} ≈ exp(t h²/12). This module measures δ of the
// chosen member on the scene's own cart and predicts the growth over a run, so that the tools can
// warn before a long paper-form run.
#pragma once

#include <string>

#include "birkhoff_cart/core/scene/scene.h"

namespace birkhoff_cart {

/// δ: the relative change of the momentum per step that the scene's integrator and form make on
/// a cart coasting straight ahead (χ = 0, ω2 = 0, no loads), whose momentum is exactly constant.
/// Zero to round-off for the autonomous form and for members that never use the chart.
double paper_form_momentum_change_per_step(const Scene& scene);

/// (1 + δ)^{duration/h} − 1: the predicted relative growth of the momenta over `duration` [s].
double paper_form_momentum_growth(const Scene& scene, double duration);

/// Relative momentum growth above which a run is warned about [-] (0.1 %: the energy grows by at
/// least twice that — by (1 + g)² − 1 on a steady turn, by ~10 g on the jackknife whirl).
constexpr double kPaperFormDriftWarningThreshold = 1e-3;

/// A one-line warning naming the predicted growth and the way out (autonomous form) when the scene's
/// run is long enough for the drift to exceed kPaperFormDriftWarningThreshold; "" otherwise.
std::string paper_form_drift_warning(const Scene& scene);

}  // namespace birkhoff_cart
