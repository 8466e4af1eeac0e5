#include "birkhoff_cart/core/run/reference_solution.h"

#include "birkhoff_cart/core/integrators/deterministic_math.h"
#include "birkhoff_cart/core/run/shadow_reference.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace birkhoff_cart {
namespace {

constexpr double kAnalyticMatchTolerance = 1e-12;  // on χ − t [rad], ω2 − 1 [rad/s], ω1 sin t − 1 [m/s]

/// Relative error |value − reference| / |reference| [-] (absolute when the reference is exactly 0).
double relative_error(double value, double reference) {
  const double difference = std::abs(value - reference);
  return reference == 0.0 ? difference : difference / std::abs(reference);
}

}  // namespace

/// Fills position, heading and arc-length errors of `state` against `reference`.
void compare_states(const CartState& state, const CartState& reference, Diagnostics& diagnostics) {
  diagnostics.has_reference = true;
  diagnostics.reference_position_error = std::hypot(state.x - reference.x, state.y - reference.y);  // [m]
  diagnostics.reference_heading_error = std::abs(state.heading - reference.heading);                // [rad]
  diagnostics.reference_arc_length_relative_error = relative_error(state.arc_length, reference.arc_length);
}

void ReferenceSolution::restart_at(const CartState& /*state*/) {
  throw std::logic_error("this reference cannot restart at a simulation event (end stops need reference none or shadow_run)");
}

namespace {

/// The paper's special case against its closed form (docs eq. (3.9)).
class PaperAnalyticReference : public ReferenceSolution {
 public:
  explicit PaperAnalyticReference(const CartState& initial) { solution_.initial = initial; }
  void step(double /*next_time*/) override {}  // closed form: nothing to integrate
  void reset() override {}
  void compare(const CartState& state, Diagnostics& diagnostics) const override {
    compare_states(state, solution_.at(state.time), diagnostics);
  }

 private:
  PaperAnalyticSolution solution_;
};

/// ln tan(t/2) [-], the antiderivative of 1/sin t on (0, π).
double log_tan_half(double time) { return deterministic::log(deterministic::tan(0.5 * time)); }

}  // namespace

CartState PaperAnalyticSolution::at(double time) const {
  const double t0 = initial.time;
  const double phase = initial.heading - t0;  // φ = θ₀ − t₀ [rad]
  const double along = (log_tan_half(time) + 2.0 * deterministic::cos(time)) - (log_tan_half(t0) + 2.0 * deterministic::cos(t0));
  const double across = 2.0 * deterministic::sin(time) - 2.0 * deterministic::sin(t0);
  CartState state = initial;
  state.time = time;
  state.steering_angle = time;                                             // χ = t
  state.forward_speed = 1.0 / deterministic::sin(time);                              // ω1 = 1/sin t
  state.steering_rate = 1.0;                                               // ω2 = 1
  state.heading = initial.heading + (time - t0);                           // θ̇ = ω1 sin χ / l = 1
  state.arc_length = initial.arc_length + log_tan_half(time) - log_tan_half(t0);  // π̇1 = 1/sin t
  state.x = initial.x + deterministic::cos(phase) * along - deterministic::sin(phase) * across;
  state.y = initial.y + deterministic::cos(phase) * across + deterministic::sin(phase) * along;
  return state;
}

bool PaperAnalyticSolution::matches(const CartState& state) {
  const double t = state.time;
  return t > 0.0 && t < M_PI && std::abs(state.steering_angle - t) <= kAnalyticMatchTolerance &&
         std::abs(state.steering_rate - 1.0) <= kAnalyticMatchTolerance &&
         std::abs(state.forward_speed * deterministic::sin(t) - 1.0) <= kAnalyticMatchTolerance;
}

std::unique_ptr<ReferenceSolution> make_reference_solution(const Scene& scene, const CartModel& model,
                                                           const EffectSet& effects) {
  switch (scene.reference.kind) {
    case ReferenceSettings::Kind::kNone:
      return nullptr;
    case ReferenceSettings::Kind::kPaperAnalytic: {
      if (model.inertia_model() != InertiaModel::kPaperSpecialCase || !effects.empty()) {
        throw std::invalid_argument(
            "reference 'paper_analytic' needs the paper's special case (paper_special_case: true) and no effects");
      }
      if (!PaperAnalyticSolution::matches(scene.initial_state)) {
        std::ostringstream message;
        message << "reference 'paper_analytic' needs an initial state on the analytic solution of eq. (3.9) "
                   "(0 < t0 < pi, steering_angle = t0, steering_rate = 1, forward_speed = 1/sin t0); got t0 = "
                << scene.initial_state.time << ", steering_angle = " << scene.initial_state.steering_angle
                << ", steering_rate = " << scene.initial_state.steering_rate
                << ", forward_speed = " << scene.initial_state.forward_speed;
        throw std::invalid_argument(message.str());
      }
      return std::make_unique<PaperAnalyticReference>(scene.initial_state);
    }
    case ReferenceSettings::Kind::kShadowRun:
      return make_shadow_reference(scene.reference.shadow, scene.integrator.step_size, scene.initial_state, model,
                                   effects);
  }
  throw std::invalid_argument("unknown reference kind");
}

}  // namespace birkhoff_cart
