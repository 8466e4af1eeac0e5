// EffectSet: the sum over the enabled effects only (a disabled effect is not in the set).
#include <stdexcept>

#include "birkhoff_cart/core/physics/effects.h"

#include "birkhoff_cart/core/physics/actuators/steering_end_stops.h"

namespace birkhoff_cart {

void EffectSet::add(std::unique_ptr<Effect> effect) {
  if (!effect) throw std::invalid_argument("EffectSet::add: null effect");
  effects_.push_back(std::move(effect));
}

GeneralizedForce EffectSet::evaluate_loads(const EffectInput& input) const {
  GeneralizedForce total;  // Q = 0, ∂Q/∂(χ, ω) = 0 for the free cart
  for (const auto& effect : effects_) effect->add_to(input, total);
  return total;
}

GeneralizedForce EffectSet::evaluate(const EffectInput& input) const {
  GeneralizedForce total = evaluate_loads(input);
  if (end_stops_) end_stops_->add_reaction(input, total);
  return total;
}

}  // namespace birkhoff_cart
