// What a scene lets a tolerance ask and a reference judge (docs/accuracy.md §4.4): the smallest
// position tolerance double precision reaches, and the smallest error its shadow reference resolves.
#pragma once

#include "birkhoff_cart/core/scene/scene.h"

namespace birkhoff_cart {

/// The scene's length scale L = max(1 m, wheelbase, |x₀|, |y₀|, |ω1₀|·duration) [m]: the size of the
/// positions a run reaches.
double scene_length_scale(const Scene& scene);

/// The smallest position tolerance [m] a step control can be asked for on `scene`: 1000 ε·L. Below
/// it the round-off of the positions and of the steps' sums (ε·L each) is no longer small against
/// the tolerance, and no member reaches it in double precision. Simulation refuses a tolerance below
/// it by name.
double position_tolerance_floor(const Scene& scene);

/// The smallest position error [m] the scene's dopri5 shadow reference resolves: 100 × its tolerance
/// × L (its own error, measured 33 × tolerance × L on the default scene over 60 s at 1e-12); 0 when the
/// scene has no dopri5 shadow run.
double shadow_reference_resolution(const Scene& scene);

}  // namespace birkhoff_cart
