// RandomSceneFamily (random_scene.h): the distributions of the random carts and scenes.
#include "birkhoff_cart/core/run/random_scene.h"

#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "birkhoff_cart/core/integrators/deterministic_math.h"
#include "birkhoff_cart/core/physics/effect_library.h"
#include "birkhoff_cart/core/run/simulation.h"

namespace birkhoff_cart {
namespace {

constexpr int kMaxDraws = 1000;  // redraws of an unusable cart before giving up (never reached in practice)

/// One draw of a scene from a seeded engine.
class SceneDraw {
 public:
  explicit SceneDraw(std::seed_seq& seeds) : engine_(seeds) {}

  double uniform(double low, double high) { return std::uniform_real_distribution<double>(low, high)(engine_); }
  double log_uniform(double low, double high) { return deterministic::exp(uniform(deterministic::log(low), deterministic::log(high))); }
  bool chance(double probability) { return uniform(0.0, 1.0) < probability; }
  int integer(int low, int high) { return std::uniform_int_distribution<int>(low, high)(engine_); }

  /// A physically plausible cart: sizes 2 cm … 5 m, masses 0.05 … 2000 kg, inertias m·L²·k with a
  /// shape factor k, wheel inertias m r² · k.
  CartParameters cart() {
    CartParameters cart;
    cart.wheelbase = log_uniform(0.02, 5.0);                      // [m]
    cart.rear_half_track = log_uniform(0.05, 2.0);                // [m]
    cart.front_half_track = log_uniform(0.05, 2.0);               // [m]
    cart.rear_wheel_radius = log_uniform(0.02, 1.0);              // [m]
    cart.front_wheel_radius = log_uniform(0.02, 1.0);             // [m]
    cart.rear_body_mass = log_uniform(0.1, 2000.0);               // [kg]
    cart.rear_body_yaw_inertia = cart.rear_body_mass * deterministic::pow(cart.wheelbase, 2) * log_uniform(0.01, 1.0);
    cart.front_axle_mass = log_uniform(0.05, 200.0);              // [kg]
    cart.front_axle_yaw_inertia = cart.front_axle_mass * deterministic::pow(cart.front_half_track, 2) * log_uniform(0.02, 0.5);
    cart.rear_wheel_mass = log_uniform(0.05, 100.0);              // [kg]
    cart.rear_wheel_spin_inertia = cart.rear_wheel_mass * deterministic::pow(cart.rear_wheel_radius, 2) * uniform(0.3, 1.0);
    cart.rear_wheel_yaw_inertia = cart.rear_wheel_mass * deterministic::pow(cart.rear_wheel_radius, 2) * uniform(0.15, 0.6);
    cart.front_wheel_mass = log_uniform(0.05, 100.0);             // [kg]
    cart.front_wheel_spin_inertia = cart.front_wheel_mass * deterministic::pow(cart.front_wheel_radius, 2) * uniform(0.3, 1.0);
    cart.front_wheel_yaw_inertia = cart.front_wheel_mass * deterministic::pow(cart.front_wheel_radius, 2) * uniform(0.15, 0.6);
    return cart;
  }

  /// χ on kπ, within 10⁻¹² … 10⁻¹ rad of it, or anywhere; ω2 often aimed through kπ.
  void steering(CartState& state) {
    const double k = integer(-2, 2);
    const double kind = uniform(0.0, 1.0);
    const double offset = kind < 0.15 ? 0.0 : kind < 0.7 ? (chance(0.5) ? 1 : -1) * log_uniform(1e-12, 1e-1)
                                                         : uniform(-M_PI, M_PI);
    state.steering_angle = k * M_PI + offset;    // [rad]
    const double rate = log_uniform(0.01, 4.0);  // [rad/s]
    state.steering_rate = (offset > 0.0 && chance(0.7)) ? -rate : (chance(0.5) ? rate : -rate);
  }

  /// The largest torque [N·m] of a random profile on `channel`: the steering torque that turns the
  /// front axle at 5 rad/s² (½ I·10), the drive torque of ½ m r (m: body and front axle).
  static double torque_amplitude(TorqueChannel channel, const CartParameters& cart) {
    if (channel == TorqueChannel::kSteering) return 0.5 * cart.front_axle_yaw_inertia * 10.0;
    return 0.5 * (cart.rear_body_mass + cart.front_axle_mass) * cart.rear_wheel_radius;
  }

  TorqueProfile torque(double amplitude) {  // amplitude [N·m]
    TorqueProfile profile;
    if (chance(0.5)) {
      profile.kind = TorqueProfile::Kind::kConstant;
      profile.value = uniform(-amplitude, amplitude);
    } else {
      profile.kind = TorqueProfile::Kind::kCosine;
      profile.amplitude = uniform(0.0, amplitude);
      profile.frequency = log_uniform(0.05, 5.0);  // [Hz]
      profile.phase = uniform(0.0, 2.0 * M_PI);    // [rad]
    }
    return profile;
  }

  Scene scene(const Scene& base) {
    Scene scene = base;
    scene.reference = ReferenceSettings{};
    scene.paper_special_case = chance(0.05);
    scene.cart = cart();
    if (scene.paper_special_case) scene.cart.wheelbase = 1.0;
    CartState state;
    state.time = chance(0.2) ? uniform(0.0, 100.0) : 0.0;  // [s]
    steering(state);
    state.forward_speed = (chance(0.8) ? 1 : -1) * log_uniform(0.01, 20.0);  // [m/s]
    state.heading = uniform(-M_PI, M_PI);                                     // [rad]
    scene.initial_state = state;
    scene.duration = uniform(0.2, 1.0);  // [s]
    scene.integrator.step_size = chance(0.5) ? 1e-3 : chance(0.5) ? 5e-3 : 1e-2;  // [s]
    scene.integrator.tolerance = 1e-8;
    scene.effects.clear();
    // Every effect of the table, in its order, with its row's chance and ranges.
    for (const EffectEntry& row : effect_table()) {
      if (!chance(row.random_chance)) continue;
      EffectSpec spec{row.name, {}, {}};
      if (row.takes_profile()) {
        spec.profile = torque(torque_amplitude(row.torque_channel, scene.cart));
      } else {
        for (const EffectCoefficient& coefficient : row.coefficients) {
          spec.coefficients[coefficient.key] = log_uniform(coefficient.random_low, coefficient.random_high);
        }
      }
      scene.effects.push_back(std::move(spec));
    }
    return scene;
  }

 private:
  std::mt19937_64 engine_;
};

}  // namespace

Scene RandomSceneFamily::scene(const Scene& base, std::uint64_t index) const {
  for (std::uint32_t draw = 0; draw < kMaxDraws; ++draw) {
    std::seed_seq seeds{static_cast<std::uint32_t>(seed_), static_cast<std::uint32_t>(seed_ >> 32),
                        static_cast<std::uint32_t>(index), static_cast<std::uint32_t>(index >> 32), draw};
    SceneDraw random(seeds);
    Scene scene = random.scene(base);
    scene.name = "random_" + std::to_string(seed_) + "_" + std::to_string(index);
    try {
      Simulation probe(scene);  // a usable cart: the mass matrix is positive definite
      return scene;
    } catch (const std::invalid_argument&) {
      continue;
    }
  }
  throw std::runtime_error("random scene " + std::to_string(index) + " of family " + std::to_string(seed_) +
                           ": no usable cart in 1000 draws");
}

}  // namespace birkhoff_cart
