// The singular steering angles of the paper's special case, and the policy for reaching them.
//
// In the paper's special case (μ = μ1 = 0, ν = 1, l = 1, docs eq. (3.9)) the mass matrix is
// M(χ) = [[0, sin χ], [sin χ, 1]] with det M(χ) = −sin²χ: it is singular at χ = kπ, where the exact
// solution has ω1 = 1/sin t → ∞ and π1 = 1 + ln tan(t/2) → ∞ (χ = t). A fixed-step scheme whose grid
// straddles t = kπ steps over the pole and lands on a finite π1, x, y that only reflect where the
// grid fell; an adaptive one stalls at the pole. Neither is a meaningful continuation.
//
// Policy (docs/hard_cases.md §1): no step may reach or cross a singular angle. The step that would
// is refused with a StepError naming the singular angle kπ and the time it would be reached; the
// simulation keeps the last state before it (steps are transactional).
//
// A physical cart has det M(χ) = I_f (m_r cos²χ + m_f + I_r sin²χ / l²) > 0 for every χ
// (docs/derivation.md): the guard never fires for it, whatever χ does (jackknife, whirl).
#pragma once

#include "birkhoff_cart/core/physics/cart_model.h"
#include "birkhoff_cart/core/physics/state.h"

namespace birkhoff_cart {

/// Whether `model`'s mass matrix is singular at some steering angle (the paper's special case).
bool has_singular_steering_angles(const CartModel& model);

/// Throws StepError when the step of size `step_size` [s] from `state` would reach or cross a
/// singular steering angle χ = kπ of `model`: the first-order prediction χ + h ω2 or, when given,
/// the stepped state `next` lies outside the open interval (kπ, (k+1)π) holding χ, or χ is
/// already singular. The message names the angle kπ [rad] and the singular time t* [s]
/// (t + (kπ − χ)/ω2; t* = kπ in the paper's case). Does nothing for a physical cart.
void check_singular_steering(const CartModel& model, const CartState& state, double step_size,
                             const CartState* next = nullptr);

}  // namespace birkhoff_cart
