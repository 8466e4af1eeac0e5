// Accuracy guards (docs/accuracy.md §2): a scene (or the node, by parameter) states the accuracy
// it needs as WARN and ERROR limits on four measured quantities; AccuracyGuard checks a running
// simulation's diagnostics against them and remembers the worst level reached, the quantity that
// reached it and when. It only observes: it never stops a run (the caller decides: cart_simulate
// exits non-zero after an ERROR, the node reports on /diagnostics and ~integration_error).
#pragma once

#include <string>
#include <vector>

#include "birkhoff_cart/core/integrators/diagnostics.h"

namespace birkhoff_cart {

enum class AccuracyLevel { kOk = 0, kWarn = 1, kError = 2 };

/// "OK", "WARN", "ERROR".
const char* to_string(AccuracyLevel level);

/// The guarded quantities, each with its scene key (accuracy.<key>).
enum class AccuracyQuantity {
  kEnergyBalanceRelative,  ///< |T* − T*₀ − ∫ω·Q dt| / max T* seen [-]   key energy_balance_relative
  kP2Balance,              ///< |p2 − p2₀ − ∫Q2 dt| [kg·m²/s]            key p2_balance
  kConstraint,             ///< max |eq. (15) residual| [m/s]            key constraint
  kEstimatedError,         ///< Σ ê, the summed local error estimates [-] key estimated_error
  kEnergyBalance,          ///< |T* − T*₀ − ∫ω·Q dt| [J]                 key energy_balance
  kNonFinite,              ///< a diagnostic that is NaN or ±∞ (always ERROR; no key)
};
constexpr int kAccuracyQuantityCount = 6;

/// The quantities with limits (every one but kNonFinite), in the order they are checked and listed:
/// the scene's `accuracy` keys, cart_sim's `~accuracy/<key>` parameters.
constexpr AccuracyQuantity kLimitedAccuracyQuantities[] = {
    AccuracyQuantity::kEnergyBalanceRelative, AccuracyQuantity::kP2Balance, AccuracyQuantity::kConstraint,
    AccuracyQuantity::kEstimatedError, AccuracyQuantity::kEnergyBalance};

/// The scene key / message name of a quantity ("energy_balance_relative", ..., "non_finite").
const char* to_string(AccuracyQuantity quantity);
/// Its unit, as printed after values ("-", "kg·m²/s", "m/s", "J").
const char* unit_of(AccuracyQuantity quantity);

/// One quantity's limits: WARN above `warn`, ERROR above `error` (0 < warn ≤ error). Disabled: never trips.
struct AccuracyLimit {
  bool enabled = false;
  double warn = 0.0;   ///< [unit of the quantity]
  double error = 0.0;  ///< [unit of the quantity]
};

/// What a scene's `accuracy` section states. The defaults (docs/accuracy.md §2) catch a run whose
/// energy balance is off by more than 1 % of T*, and raise no alarm on the shipped scenes.
struct AccuracyRequirements {
  AccuracyLimit energy_balance_relative{true, 1e-4, 1e-2};  ///< [-]
  AccuracyLimit p2_balance{};                               ///< [kg·m²/s], off by default
  AccuracyLimit constraint{true, 1e-9, 1e-6};               ///< [m/s]
  AccuracyLimit estimated_error{};                          ///< [-], off by default
  AccuracyLimit energy_balance{};                           ///< [J], off by default (absolute: scale-dependent)

  const AccuracyLimit& limit(AccuracyQuantity quantity) const;
  AccuracyLimit& limit(AccuracyQuantity quantity);
};

/// Throws std::invalid_argument naming the quantity when a limit is not 0 < warn ≤ error, finite.
void validate(const AccuracyRequirements& requirements);

/// The first time one quantity reached one level.
struct AccuracyEvent {
  AccuracyQuantity quantity = AccuracyQuantity::kEnergyBalanceRelative;
  AccuracyLevel level = AccuracyLevel::kOk;
  double time = 0.0;   ///< scene time of the check [s]
  double value = 0.0;  ///< the quantity then [its unit]
  double limit = 0.0;  ///< the limit it exceeded [its unit] (NaN for kNonFinite)
};

class AccuracyGuard {
 public:
  explicit AccuracyGuard(const AccuracyRequirements& requirements = AccuracyRequirements());

  /// Checks the state at scene time `time` [s] and returns this check's level. Keeps the worst
  /// level and the first event of each (quantity, level). The energy scale is the largest T* seen
  /// at the checks so far: check the initial state first.
  AccuracyLevel check(double time, const Diagnostics& diagnostics, const StepStatistics& statistics);

  /// Worst level since construction/reset.
  AccuracyLevel level() const { return level_; }
  /// The last check's level and value of each quantity.
  AccuracyLevel current_level() const { return current_level_; }
  double current_value(AccuracyQuantity quantity) const { return current_[static_cast<int>(quantity)]; }
  /// Largest value of each quantity over the checks [its unit].
  double largest_value(AccuracyQuantity quantity) const { return largest_[static_cast<int>(quantity)]; }
  /// First events in the order they happened (at most one per quantity and level).
  const std::vector<AccuracyEvent>& events() const { return events_; }
  /// The first event of the worst level ("nothing" when OK).
  const AccuracyEvent* first_worst_event() const;

  /// One line: "OK" or "ERROR: energy_balance_relative 0.92 > 0.01 (first at t = 1.234 s); ...".
  std::string summary() const;
  /// One line for the current check: the quantities above their WARN limit now.
  std::string current_summary() const;

  const AccuracyRequirements& requirements() const { return requirements_; }
  /// New limits while running (cart_sim's dynamic_reconfigure): they judge the checks from now on;
  /// the levels and events reached so far stay. Throws std::invalid_argument (validate()) with
  /// nothing changed.
  void set_requirements(const AccuracyRequirements& requirements);
  void reset();

 private:
  AccuracyRequirements requirements_;
  AccuracyLevel level_ = AccuracyLevel::kOk;
  AccuracyLevel current_level_ = AccuracyLevel::kOk;
  double energy_scale_ = 0.0;  ///< max T* seen [J]
  double current_[kAccuracyQuantityCount] = {};
  double largest_[kAccuracyQuantityCount] = {};
  AccuracyLevel reached_[kAccuracyQuantityCount] = {};
  std::vector<AccuracyEvent> events_;
};

}  // namespace birkhoff_cart
