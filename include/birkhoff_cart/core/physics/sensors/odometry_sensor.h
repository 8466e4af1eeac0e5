// A wheel-odometry sensor of the cart, enabled by a scene's `odometry_sensor` section: encoders on
// the two rear wheels and on the steering hinge, an optional yaw-rate gyro, read at the caller's
// instants (the node's publish instants, the CLI's rows), and the pose of base_link (the rear-axle
// midpoint A) dead-reckoned from those readings, with its covariance propagated from the noise
// model. Equations: docs/odometry_sensor.md (eqs. (O1)–(O7)). Deterministic for a seed: the noise
// is drawn from its own mt19937_64 stream by a fixed Box–Muller transform, never from the library's
// distributions (whose algorithm is unspecified).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <random>
#include <string>

#include "birkhoff_cart/core/physics/cart_model.h"
#include "birkhoff_cart/core/physics/state.h"

namespace birkhoff_cart {

/// Where the dead reckoning takes the heading increment from (eq. (O3)).
enum class HeadingSource {
  kWheels,    ///< Δθ̂ = (d̂R − d̂L) / 2a, the rear wheels' difference
  kSteering,  ///< Δθ̂ = Δŝ tan χ̄ / l, the steering encoder (bicycle kinematics of A, eq. (2.3))
  kGyro,      ///< Δθ̂ = ĝ Δt, the yaw-rate gyro
};
HeadingSource heading_source_from_string(const std::string& name);  ///< throws std::invalid_argument
const char* to_string(HeadingSource source);

/// The scene's `odometry_sensor` section (docs/scenes.md). All noise is off at the defaults: a
/// sensor with default settings dead-reckons the true path up to its discretization.
struct OdometrySensorSettings {
  std::uint64_t seed = 1;                      ///< of the noise stream [-]
  std::uint32_t wheel_encoder_counts = 0;      ///< counts per rear wheel revolution; 0 = exact angle [1/rev]
  std::array<double, 2> wheel_radius_error{};  ///< e_L, e_R: the odometry takes r (1 + e) for the true r [-]
  double wheel_distance_noise = 0.0;           ///< σ_w: noise of a wheel's rolled distance per √(metre rolled) [m/√m]
  HeadingSource heading_source = HeadingSource::kWheels;
  std::uint32_t steering_encoder_counts = 0;   ///< counts per revolution of the hinge; 0 = exact [1/rev]
  double steering_offset = 0.0;                ///< error of the steering encoder's zero [rad]
  double steering_noise = 0.0;                 ///< σ_χ: noise of each steering reading [rad]
  double gyro_noise_density = 0.0;             ///< σ_g: white rate noise [rad/s/√Hz]
  double gyro_bias = 0.0;                      ///< constant rate bias [rad/s]
};

/// Refuses settings that cannot describe a sensor (std::invalid_argument naming the setting).
void validate(const OdometrySensorSettings& settings);

/// The dead-reckoned odometry at the last reading (what the node publishes on `odom`).
struct OdometryEstimate {
  double time = 0.0;          ///< of the last reading [s]
  double x = 0.0;             ///< x̂ of A in the odom frame [m]
  double y = 0.0;             ///< ŷ of A [m]
  double heading = 0.0;       ///< θ̂ [rad]
  double speed = 0.0;         ///< v̂_A = Δŝ/Δt over the last interval [m/s]
  double heading_rate = 0.0;  ///< Δθ̂/Δt over the last interval [rad/s]
  /// Covariance of (x̂, ŷ, θ̂) from the random noise (eq. (O6)); biases are not in it [m², m·rad, rad²].
  Eigen::Matrix3d pose_covariance = Eigen::Matrix3d::Zero();
  /// Covariance of (v̂_A, θ̂̇) over the last interval (eq. (O7)) [m²/s², m·rad/s², rad²/s²].
  Eigen::Matrix2d twist_covariance = Eigen::Matrix2d::Zero();
  double distance = 0.0;       ///< Σ|Δŝ| since start(): the distance the odometry has rolled [m]
  std::uint64_t readings = 0;  ///< readings since start()
};

class OdometrySensor {
 public:
  /// Throws std::invalid_argument naming a bad setting (validate()).
  OdometrySensor(const OdometrySensorSettings& settings, const CartModel& model);

  /// Dead reckoning starts at the true pose of `state` with covariance 0, and the encoders are read
  /// there. `reseed`: the noise stream starts again at the seed (a reset: the run again bit for bit);
  /// otherwise it goes on (a teleport).
  void start(const CartState& state, bool reseed);
  /// Reads the sensors at `state` and dead-reckons to it (eqs. (O1)–(O6)). A state at the time of
  /// the last reading returns the estimate unchanged. Throws std::logic_error before start() or for
  /// a time before the last reading.
  const OdometryEstimate& read(const CartState& state);

  const OdometryEstimate& estimate() const { return estimate_; }
  const OdometrySensorSettings& settings() const { return settings_; }
  bool started() const { return started_; }

 private:
  /// What the encoders show: the counted angle, floor(φ N / 2π) 2π/N, or φ when N = 0 [rad].
  static double encoder_angle(double angle, std::uint32_t counts_per_revolution);
  double standard_normal();
  /// χ̂ = counted χ + offset + noise [rad] (draws one normal).
  double read_steering(double steering_angle);

  OdometrySensorSettings settings_;
  double rear_wheel_radius_ = 0.0;  ///< r1 [m]
  double rear_half_track_ = 0.0;    ///< a [m]
  double wheelbase_ = 0.0;          ///< l [m]
  double steering_reading_variance_ = 0.0;  ///< σ_χ² + q²/12 of one steering reading [rad²]
  std::mt19937_64 noise_stream_;
  double spare_normal_ = 0.0;
  bool has_spare_normal_ = false;
  bool started_ = false;
  // At the last reading:
  std::array<double, 2> true_wheel_angle_{};     ///< φ1, φ2 [rad]
  std::array<double, 2> counted_wheel_angle_{};  ///< the encoders' angles [rad]
  double steering_reading_ = 0.0;                ///< χ̂ [rad]
  double true_heading_ = 0.0;                    ///< θ, for the gyro's mean rate [rad]
  /// Covariance of (x̂, ŷ, θ̂, n) where n is the last steering reading's noise, shared by the next
  /// interval's mean steering angle (heading_source steering; zero otherwise).
  Eigen::Matrix4d covariance_ = Eigen::Matrix4d::Zero();
  OdometryEstimate estimate_;
};

/// One sentence for run summaries, "Odometry sensor (...): ...": how far the sensor's estimate is
/// from `truth` (position of A [m], heading [rad]) against its covariance's standard deviations.
std::string odometry_drift_line(const OdometrySensor& sensor, const CartState& truth, const CartModel& model);

}  // namespace birkhoff_cart
