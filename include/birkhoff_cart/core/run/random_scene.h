// A seeded family of random valid carts and scenes, for robustness studies and tests
// (docs/accuracy.md §3): masses, inertias and geometry over physical ranges (log-uniform),
// steering angles on, through and near χ = kπ, each effect of the effect table on or off (its
// row's chance and ranges: effect_library.h), a few of the paper's singular special case. Scene k
// of family `seed` depends on (seed, k) alone, so a study can run any index on any worker, and the
// unit test and `cart_simulate --random-scene SEED:K` draw the very same carts.
#pragma once

#include <cstdint>
#include <random>

#include "birkhoff_cart/core/scene/scene.h"

namespace birkhoff_cart {

class RandomSceneFamily {
 public:
  explicit RandomSceneFamily(std::uint64_t seed) : seed_(seed) {}

  /// Scene `index` of the family: `base` (for what the family does not draw: the accuracy guard,
  /// output rate) with a random cart, start, duration (0.2 … 1 s), step (1, 5 or 10 ms) and
  /// effects. Draws that give an unusable cart (Simulation refuses its mass matrix) are redrawn,
  /// so the scene returned builds a Simulation. Its name is "random_<seed>_<index>".
  Scene scene(const Scene& base, std::uint64_t index) const;

 private:
  std::uint64_t seed_;
};

}  // namespace birkhoff_cart
