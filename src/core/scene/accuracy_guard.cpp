#include "birkhoff_cart/core/scene/accuracy_guard.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

namespace birkhoff_cart {
namespace {

int index_of(AccuracyQuantity quantity) { return static_cast<int>(quantity); }

std::string format_number(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", value);
  return text;
}

/// " kg·m²/s" after a value, nothing for a dimensionless quantity.
std::string unit_suffix(AccuracyQuantity quantity) {
  const std::string unit = unit_of(quantity);
  return unit == "-" ? "" : " " + unit;
}

std::string describe(const AccuracyEvent& event) {
  std::string line = to_string(event.quantity);
  if (event.quantity == AccuracyQuantity::kNonFinite) return line + " diagnostic at t = " + format_number(event.time) + " s";
  line += " " + format_number(event.value) + " > " + format_number(event.limit) + unit_suffix(event.quantity) +
          " (first at t = " + format_number(event.time) + " s)";
  return line;
}

}  // namespace

const char* to_string(AccuracyLevel level) {
  switch (level) {
    case AccuracyLevel::kOk: return "OK";
    case AccuracyLevel::kWarn: return "WARN";
    case AccuracyLevel::kError: return "ERROR";
  }
  return "?";
}

const char* to_string(AccuracyQuantity quantity) {
  switch (quantity) {
    case AccuracyQuantity::kEnergyBalanceRelative: return "energy_balance_relative";
    case AccuracyQuantity::kP2Balance: return "p2_balance";
    case AccuracyQuantity::kConstraint: return "constraint";
    case AccuracyQuantity::kEstimatedError: return "estimated_error";
    case AccuracyQuantity::kEnergyBalance: return "energy_balance";
    case AccuracyQuantity::kNonFinite: return "non_finite";
  }
  return "?";
}

const char* unit_of(AccuracyQuantity quantity) {
  switch (quantity) {
    case AccuracyQuantity::kP2Balance: return "kg·m²/s";
    case AccuracyQuantity::kConstraint: return "m/s";
    case AccuracyQuantity::kEnergyBalance: return "J";
    default: return "-";
  }
}

const AccuracyLimit& AccuracyRequirements::limit(AccuracyQuantity quantity) const {
  switch (quantity) {
    case AccuracyQuantity::kEnergyBalanceRelative: return energy_balance_relative;
    case AccuracyQuantity::kP2Balance: return p2_balance;
    case AccuracyQuantity::kConstraint: return constraint;
    case AccuracyQuantity::kEstimatedError: return estimated_error;
    case AccuracyQuantity::kEnergyBalance: return energy_balance;
    case AccuracyQuantity::kNonFinite: break;
  }
  throw std::invalid_argument("non_finite has no limit");
}

AccuracyLimit& AccuracyRequirements::limit(AccuracyQuantity quantity) {
  return const_cast<AccuracyLimit&>(static_cast<const AccuracyRequirements&>(*this).limit(quantity));
}

void validate(const AccuracyRequirements& requirements) {
  for (AccuracyQuantity quantity : kLimitedAccuracyQuantities) {
    const AccuracyLimit& limit = requirements.limit(quantity);
    if (!limit.enabled) continue;
    if (!std::isfinite(limit.warn) || !std::isfinite(limit.error) || !(limit.warn > 0.0) ||
        !(limit.warn <= limit.error)) {
      throw std::invalid_argument(std::string("accuracy limit ") + to_string(quantity) + " needs 0 < warn <= error, finite; got warn = " +
                                  format_number(limit.warn) + ", error = " + format_number(limit.error));
    }
  }
}

AccuracyGuard::AccuracyGuard(const AccuracyRequirements& requirements) : requirements_(requirements) {
  validate(requirements_);
}

void AccuracyGuard::set_requirements(const AccuracyRequirements& requirements) {
  validate(requirements);
  requirements_ = requirements;
}

void AccuracyGuard::reset() {
  *this = AccuracyGuard(requirements_);
}

AccuracyLevel AccuracyGuard::check(double time, const Diagnostics& diagnostics, const StepStatistics& statistics) {
  if (std::isfinite(diagnostics.energy)) energy_scale_ = std::max(energy_scale_, std::abs(diagnostics.energy));
  const double energy_residual = std::abs(diagnostics.energy_balance_residual);  // [J]
  // |T* − T*₀ − W| / max T*; 0/0 (a cart at rest, unforced) is no error, r/0 is.
  double& relative = current_[index_of(AccuracyQuantity::kEnergyBalanceRelative)];
  relative = energy_scale_ > 0.0 ? energy_residual / energy_scale_
             : energy_residual == 0.0 ? 0.0 : std::numeric_limits<double>::infinity();
  if (std::isnan(energy_residual)) relative = energy_residual;
  current_[index_of(AccuracyQuantity::kEnergyBalance)] = energy_residual;
  current_[index_of(AccuracyQuantity::kP2Balance)] = std::abs(diagnostics.p2_balance_residual);
  current_[index_of(AccuracyQuantity::kConstraint)] = std::abs(diagnostics.max_constraint_residual);
  current_[index_of(AccuracyQuantity::kEstimatedError)] =
      has_local_error_estimate(statistics) ? statistics.local_error_estimate_sum : 0.0;
  const bool non_finite = !std::isfinite(diagnostics.energy) || !std::isfinite(diagnostics.energy_balance_residual) ||
                          !std::isfinite(diagnostics.p2_balance_residual) ||
                          !std::isfinite(diagnostics.max_constraint_residual) ||
                          !std::isfinite(current_[index_of(AccuracyQuantity::kEstimatedError)]);
  current_[index_of(AccuracyQuantity::kNonFinite)] = non_finite ? 1.0 : 0.0;

  auto note = [&](AccuracyQuantity quantity, AccuracyLevel level, double limit) {
    const int i = index_of(quantity);
    current_level_ = std::max(current_level_, level);
    if (level <= reached_[i]) return;
    // A jump straight from OK to ERROR passed WARN at the same check: record both, in order.
    if (level == AccuracyLevel::kError && reached_[i] == AccuracyLevel::kOk && quantity != AccuracyQuantity::kNonFinite) {
      events_.push_back({quantity, AccuracyLevel::kWarn, time, current_[i], requirements_.limit(quantity).warn});
    }
    reached_[i] = level;
    events_.push_back({quantity, level, time, current_[i], limit});
  };

  current_level_ = AccuracyLevel::kOk;
  for (AccuracyQuantity quantity : kLimitedAccuracyQuantities) {
    const int i = index_of(quantity);
    const double value = current_[i];
    if (!std::isnan(value)) largest_[i] = std::max(largest_[i], value);
    const AccuracyLimit& limit = requirements_.limit(quantity);
    if (!limit.enabled || std::isnan(value)) continue;  // NaN: reported as non_finite
    if (value > limit.error) note(quantity, AccuracyLevel::kError, limit.error);
    else if (value > limit.warn) note(quantity, AccuracyLevel::kWarn, limit.warn);
  }
  if (non_finite) {
    largest_[index_of(AccuracyQuantity::kNonFinite)] = 1.0;
    note(AccuracyQuantity::kNonFinite, AccuracyLevel::kError, std::nan(""));
  }
  level_ = std::max(level_, current_level_);
  return current_level_;
}

const AccuracyEvent* AccuracyGuard::first_worst_event() const {
  for (const AccuracyEvent& event : events_) {
    if (event.level == level_) return &event;
  }
  return nullptr;
}

std::string AccuracyGuard::summary() const {
  if (level_ == AccuracyLevel::kOk) return "OK";
  std::string line = to_string(level_);
  line += ":";
  bool first = true;
  for (const AccuracyEvent& event : events_) {
    if (event.level != level_) continue;
    line += (first ? " " : "; ") + describe(event);
    first = false;
  }
  return line;
}

std::string AccuracyGuard::current_summary() const {
  if (current_level_ == AccuracyLevel::kOk) return "OK";
  std::string line = to_string(current_level_);
  line += ":";
  bool first = true;
  for (AccuracyQuantity quantity : kLimitedAccuracyQuantities) {
    const AccuracyLimit& limit = requirements_.limit(quantity);
    const double value = current_[index_of(quantity)];
    if (!limit.enabled || !(value > limit.warn)) continue;
    line += std::string(first ? " " : "; ") + to_string(quantity) + " " + format_number(value) + " > " +
            format_number(value > limit.error ? limit.error : limit.warn) + unit_suffix(quantity);
    first = false;
  }
  if (current_[index_of(AccuracyQuantity::kNonFinite)] != 0.0) line += std::string(first ? " " : "; ") + "non_finite diagnostic";
  return line;
}

}  // namespace birkhoff_cart
