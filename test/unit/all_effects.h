// Every effect of the effect table (effect_library.h) on, each with its row's typical coefficients
// or torque profile (a cosine steering torque, a constant drive torque: non-trivial time profiles and
// state-dependent Jacobians): the effect set of the tests that check the cart's rates and their
// derivatives with every load acting (cart_birkhoffian_test, cart_jacobian_test, effects_test). A new
// row of the table is in it without a change here. Header-only: every test/unit/*.cpp is its own
// executable.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include "birkhoff_cart/core/physics/effect_library.h"
#include "birkhoff_cart/core/physics/effect_spec.h"

namespace birkhoff_cart_test {

/// The spec of the table's row `name` with its typical values.
inline birkhoff_cart::EffectSpec typical_effect_spec(const std::string& name) {
  const birkhoff_cart::EffectEntry& row = birkhoff_cart::effect_entry(name);
  birkhoff_cart::EffectSpec spec;
  spec.name = row.name;
  if (row.takes_profile()) spec.profile = row.typical_profile;
  for (const birkhoff_cart::EffectCoefficient& coefficient : row.coefficients) {
    spec.coefficients[coefficient.key] = coefficient.typical;
  }
  return spec;
}

/// Every row of the table, in its order, with its typical values.
inline std::vector<birkhoff_cart::EffectSpec> all_effect_specs() {
  std::vector<birkhoff_cart::EffectSpec> specs;
  for (const std::string& name : birkhoff_cart::effect_names()) specs.push_back(typical_effect_spec(name));
  return specs;
}

}  // namespace birkhoff_cart_test
