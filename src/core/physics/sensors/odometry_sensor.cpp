// Wheel odometry of the cart: readings, dead reckoning and covariance (see odometry_sensor.h and
// docs/odometry_sensor.md for eqs. (O1)–(O7)).
#include "birkhoff_cart/core/physics/sensors/odometry_sensor.h"
#include "birkhoff_cart/core/integrators/deterministic_math.h"

#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

namespace birkhoff_cart {
namespace {

constexpr double kTwoPi = 6.283185307179586476925286766559;

void require(bool condition, const std::string& message) {
  if (!condition) throw std::invalid_argument("odometry_sensor: " + message);
}

}  // namespace

HeadingSource heading_source_from_string(const std::string& name) {
  if (name == "wheels") return HeadingSource::kWheels;
  if (name == "steering") return HeadingSource::kSteering;
  if (name == "gyro") return HeadingSource::kGyro;
  throw std::invalid_argument("odometry_sensor: heading_source must be wheels, steering or gyro, got '" + name + "'");
}

const char* to_string(HeadingSource source) {
  switch (source) {
    case HeadingSource::kWheels: return "wheels";
    case HeadingSource::kSteering: return "steering";
    case HeadingSource::kGyro: return "gyro";
  }
  return "?";
}

void validate(const OdometrySensorSettings& settings) {
  for (int wheel = 0; wheel < 2; ++wheel) {
    const double error = settings.wheel_radius_error[wheel];
    require(std::isfinite(error) && std::abs(error) < 0.5,
            "wheel_radius_error must be finite and within (-0.5, 0.5), got " + std::to_string(error));
  }
  require(std::isfinite(settings.wheel_distance_noise) && settings.wheel_distance_noise >= 0.0,
          "wheel_distance_noise must be finite and >= 0 m/sqrt(m)");
  require(std::isfinite(settings.steering_offset), "steering_offset must be finite [rad]");
  require(std::isfinite(settings.steering_noise) && settings.steering_noise >= 0.0,
          "steering_noise must be finite and >= 0 rad");
  require(std::isfinite(settings.gyro_noise_density) && settings.gyro_noise_density >= 0.0,
          "gyro_noise_density must be finite and >= 0 rad/s/sqrt(Hz)");
  require(std::isfinite(settings.gyro_bias), "gyro_bias must be finite [rad/s]");
}

OdometrySensor::OdometrySensor(const OdometrySensorSettings& settings, const CartModel& model)
    : settings_(settings),
      rear_wheel_radius_(model.parameters().rear_wheel_radius),
      rear_half_track_(model.parameters().rear_half_track),
      wheelbase_(model.parameters().wheelbase) {
  validate(settings_);
  // One steering reading's random error: the noise and the counting, taken as uniform over one
  // count (variance q²/12) and independent between readings (eq. (O2)).
  const double count = settings_.steering_encoder_counts > 0 ? kTwoPi / settings_.steering_encoder_counts : 0.0;
  steering_reading_variance_ = settings_.steering_noise * settings_.steering_noise + count * count / 12.0;
}

double OdometrySensor::encoder_angle(double angle, std::uint32_t counts_per_revolution) {
  if (counts_per_revolution == 0) return angle;
  const double counts = static_cast<double>(counts_per_revolution);
  return std::floor(angle * counts / kTwoPi) * kTwoPi / counts;  // eq. (O1)
}

double OdometrySensor::standard_normal() {
  // Box–Muller on two uniform doubles of (0, 1] built from 53 bits each: the same numbers on every
  // platform for a seed.
  if (has_spare_normal_) {
    has_spare_normal_ = false;
    return spare_normal_;
  }
  constexpr double kUnit = 1.0 / 9007199254740992.0;  // 2^-53
  const double u1 = (static_cast<double>(noise_stream_() >> 11) + 1.0) * kUnit;
  const double u2 = static_cast<double>(noise_stream_() >> 11) * kUnit;
  const double radius = std::sqrt(-2.0 * deterministic::log(u1));
  spare_normal_ = radius * deterministic::sin(kTwoPi * u2);
  has_spare_normal_ = true;
  return radius * deterministic::cos(kTwoPi * u2);
}

double OdometrySensor::read_steering(double steering_angle) {
  return encoder_angle(steering_angle, settings_.steering_encoder_counts) + settings_.steering_offset +
         settings_.steering_noise * standard_normal();  // eq. (O2)
}

void OdometrySensor::start(const CartState& state, bool reseed) {
  if (reseed || !started_) {
    noise_stream_.seed(settings_.seed);
    has_spare_normal_ = false;
  }
  for (int wheel = 0; wheel < 2; ++wheel) {
    true_wheel_angle_[wheel] = state.wheel_spin_angle[wheel];
    counted_wheel_angle_[wheel] = encoder_angle(state.wheel_spin_angle[wheel], settings_.wheel_encoder_counts);
  }
  steering_reading_ = read_steering(state.steering_angle);
  true_heading_ = state.heading;
  estimate_ = OdometryEstimate{};
  estimate_.time = state.time;
  // A = B − l (cos θ, sin θ): the estimate starts at the true pose.
  estimate_.x = state.x - wheelbase_ * deterministic::cos(state.heading);
  estimate_.y = state.y - wheelbase_ * deterministic::sin(state.heading);
  estimate_.heading = state.heading;
  covariance_.setZero();
  if (settings_.heading_source == HeadingSource::kSteering) covariance_(3, 3) = steering_reading_variance_;
  started_ = true;
}

const OdometryEstimate& OdometrySensor::read(const CartState& state) {
  if (!started_) throw std::logic_error("OdometrySensor::read before start()");
  const double interval = state.time - estimate_.time;  // Δt [s]
  if (interval == 0.0) return estimate_;
  if (!(interval > 0.0)) throw std::logic_error("OdometrySensor::read: time before the last reading");

  // Rolled distances of the rear wheels as the odometry sees them (eq. (O1)) [m], and the variance
  // of their noise [m²]. Four normals per reading in a fixed order, used or not, so that a setting
  // switched off does not shift the others' noise.
  const double wheel_normal[2] = {standard_normal(), standard_normal()};
  std::array<double, 2> distance{};
  std::array<double, 2> distance_variance{};
  for (int wheel = 0; wheel < 2; ++wheel) {
    const double counted = encoder_angle(state.wheel_spin_angle[wheel], settings_.wheel_encoder_counts);
    const double true_distance = rear_wheel_radius_ * (state.wheel_spin_angle[wheel] - true_wheel_angle_[wheel]);
    distance[wheel] = rear_wheel_radius_ * (1.0 + settings_.wheel_radius_error[wheel]) *
                          (counted - counted_wheel_angle_[wheel]) +
                      settings_.wheel_distance_noise * std::sqrt(std::abs(true_distance)) * wheel_normal[wheel];
    distance_variance[wheel] = settings_.wheel_distance_noise * settings_.wheel_distance_noise * std::abs(distance[wheel]);
    true_wheel_angle_[wheel] = state.wheel_spin_angle[wheel];
    counted_wheel_angle_[wheel] = counted;
  }
  const double previous_steering_reading = steering_reading_;
  steering_reading_ = read_steering(state.steering_angle);
  // The gyro's mean rate over the interval, biased and noisy (eq. (O4)) [rad/s].
  const double gyro_rate = (state.heading - true_heading_) / interval + settings_.gyro_bias +
                           settings_.gyro_noise_density / std::sqrt(interval) * standard_normal();
  true_heading_ = state.heading;

  // Increments (eq. (O3)) and their sensitivities to the inputs (δL, δR, η, n_prev): δL, δR the
  // wheels' distance noise, η the new steering reading's error or the gyro's, n_prev the previous
  // steering reading's error.
  const double forward = 0.5 * (distance[0] + distance[1]);  // Δŝ [m]
  Eigen::Vector4d forward_sensitivity(0.5, 0.5, 0.0, 0.0);
  Eigen::Vector4d heading_sensitivity = Eigen::Vector4d::Zero();
  double heading_increment = 0.0;  // Δθ̂ [rad]
  double input_variance = 0.0;     // of η [rad²]
  switch (settings_.heading_source) {
    case HeadingSource::kWheels:
      heading_increment = (distance[1] - distance[0]) / (2.0 * rear_half_track_);
      heading_sensitivity << -0.5 / rear_half_track_, 0.5 / rear_half_track_, 0.0, 0.0;
      break;
    case HeadingSource::kSteering: {
      const double tangent = deterministic::tan(0.5 * (previous_steering_reading + steering_reading_));  // tan χ̄
      heading_increment = forward * tangent / wheelbase_;
      const double per_reading = forward * (1.0 + tangent * tangent) / (2.0 * wheelbase_);  // ∂Δθ̂/∂χ̂_k
      heading_sensitivity << tangent / (2.0 * wheelbase_), tangent / (2.0 * wheelbase_), per_reading, per_reading;
      input_variance = steering_reading_variance_;
      break;
    }
    case HeadingSource::kGyro:
      heading_increment = gyro_rate * interval;
      heading_sensitivity << 0.0, 0.0, 1.0, 0.0;
      input_variance = settings_.gyro_noise_density * settings_.gyro_noise_density * interval;
      break;
  }

  // Dead reckoning along the arc of constant curvature through the increments (eq. (O5)): the
  // chord Δŝ·sinc(Δθ̂/2) on the mean heading θ̂ + Δθ̂/2.
  const double half_turn = 0.5 * heading_increment;  // u [rad]
  double chord_factor = 1.0;                           // sin u / u [-]
  double chord_factor_slope = 0.0;                     // d(sin u / u)/dΔθ̂ [1/rad]
  if (std::abs(half_turn) > 1e-4) {
    chord_factor = deterministic::sin(half_turn) / half_turn;
    chord_factor_slope = 0.5 * (deterministic::cos(half_turn) - chord_factor) / half_turn;
  } else {  // the series: sin u/u = 1 − u²/6 + u⁴/120, its error below 1e-24
    const double square = half_turn * half_turn;
    chord_factor = 1.0 - square / 6.0 + square * square / 120.0;
    chord_factor_slope = 0.5 * half_turn * (-1.0 / 3.0 + square / 30.0);
  }
  const double chord = forward * chord_factor;  // [m]
  const double mean_heading = estimate_.heading + half_turn;
  const double cosine = deterministic::cos(mean_heading);
  const double sine = deterministic::sin(mean_heading);
  estimate_.x += chord * cosine;
  estimate_.y += chord * sine;
  estimate_.heading += heading_increment;
  estimate_.speed = forward / interval;
  estimate_.heading_rate = heading_increment / interval;
  estimate_.time = state.time;
  estimate_.distance += std::abs(forward);
  ++estimate_.readings;

  // Covariance propagation (eq. (O6)): (x, y, θ, n) ← J (x, y, θ, n_prev, δL, δR, η).
  using Matrix47 = Eigen::Matrix<double, 4, 7>;
  using Matrix77 = Eigen::Matrix<double, 7, 7>;
  const int kInputColumn[4] = {4, 5, 6, 3};  // δL, δR, η, n_prev → columns of J
  Matrix47 jacobian = Matrix47::Zero();
  jacobian(0, 0) = 1.0;
  jacobian(1, 1) = 1.0;
  jacobian(2, 2) = 1.0;
  jacobian(0, 2) = -chord * sine;
  jacobian(1, 2) = chord * cosine;
  // ∂(chord cos θm)/∂Δθ̂ = Δŝ k' cos θm − chord sin θm / 2, likewise for y.
  const double chord_x_turn = forward * chord_factor_slope * cosine - 0.5 * chord * sine;
  const double chord_y_turn = forward * chord_factor_slope * sine + 0.5 * chord * cosine;
  for (int input = 0; input < 4; ++input) {
    const int column = kInputColumn[input];
    jacobian(0, column) += chord_factor * cosine * forward_sensitivity(input) + chord_x_turn * heading_sensitivity(input);
    jacobian(1, column) += chord_factor * sine * forward_sensitivity(input) + chord_y_turn * heading_sensitivity(input);
    jacobian(2, column) += heading_sensitivity(input);
  }
  if (settings_.heading_source == HeadingSource::kSteering) jacobian(3, 6) = 1.0;  // n ← η
  Matrix77 inputs = Matrix77::Zero();
  inputs.topLeftCorner<4, 4>() = covariance_;
  inputs(4, 4) = distance_variance[0];
  inputs(5, 5) = distance_variance[1];
  inputs(6, 6) = input_variance;
  const Eigen::Matrix4d propagated = jacobian * inputs * jacobian.transpose();
  covariance_ = 0.5 * (propagated + propagated.transpose());  // exactly symmetric, as a covariance message must be
  estimate_.pose_covariance = covariance_.topLeftCorner<3, 3>();

  // Twist covariance of (Δŝ, Δθ̂)/Δt over this interval (eq. (O7)).
  Eigen::Matrix<double, 2, 7> rates = Eigen::Matrix<double, 2, 7>::Zero();
  for (int input = 0; input < 4; ++input) {
    rates(0, kInputColumn[input]) = forward_sensitivity(input);
    rates(1, kInputColumn[input]) = heading_sensitivity(input);
  }
  const Eigen::Matrix2d twist = rates * inputs * rates.transpose() / (interval * interval);
  estimate_.twist_covariance = 0.5 * (twist + twist.transpose());
  return estimate_;
}

std::string odometry_drift_line(const OdometrySensor& sensor, const CartState& truth, const CartModel& model) {
  const OdometryEstimate& estimate = sensor.estimate();
  const Eigen::Vector2d rear_axle = model.rear_axle_midpoint(truth);
  const double position_error = std::hypot(estimate.x - rear_axle.x(), estimate.y - rear_axle.y());  // [m]
  const double heading_error = estimate.heading - truth.heading;                                   // [rad]
  char line[400];
  std::snprintf(line, sizeof line,
                "Odometry sensor (heading from %s, seed %llu): after %.4g m rolled the estimate is %.3g m and %.3g "
                "rad off the truth; its covariance gives 1 sigma %.3g m and %.3g rad (random noise only; "
                "docs/odometry_sensor.md)",
                to_string(sensor.settings().heading_source), static_cast<unsigned long long>(sensor.settings().seed),
                estimate.distance, position_error, heading_error,
                std::sqrt(estimate.pose_covariance(0, 0) + estimate.pose_covariance(1, 1)),
                std::sqrt(estimate.pose_covariance(2, 2)));
  return line;
}

}  // namespace birkhoff_cart
