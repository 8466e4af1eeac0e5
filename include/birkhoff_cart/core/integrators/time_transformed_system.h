// A Birkhoffian system under a Sundman time transformation (docs/birkhoffian.md §11, eqs.
// (B.41)–(B.43)): with a step density σ(z) > 0 [1/s] (how fast the motion turns there) and the
// fictive time τ, dt/dτ = 1/σ(z),
//
//   dw/dτ = ẇ(w, t) / σ(z),   dy/dτ = g(z, y, t) / σ(z),   dt/dτ = 1 / σ(z),              (B.41)
//
// and time t is one more passive coordinate (the last of y). A collocation member applied to this
// system with a constant fictive step ε is a symmetric map of (z, y, t) (the extended system is
// autonomous in τ and σ reads z alone), whose physical steps h = ε Σⱼ bⱼ/σ(Zⱼ) ≈ ε/σ are long where
// the motion is slow and short where it turns fast (Hairer 1997; Hairer & Stoffer 1997; GNI §VIII.2).
// With σ even under the reversal p ↦ −p the map keeps the reversibility of the free cart; the
// passive quadrature gives t exactly as the same collocation gives y, compensated.
//
// For loads that do not depend on time (the free cart, autonomous drag, springs, dampers, held
// commands): ẇ is evaluated at the step's start time, which it does not read. The system supplies
// σ as `step_density(z)` (a function of z alone, any scalar type; optional: system_traits.h, default
// 1 s⁻¹); its gradient for the Jacobian comes from forward-mode AD.
//
// The optional hooks of system_traits.h carry over: the cyclic mask (σ must not read a cyclic
// coordinate either), the passive coupling depth (1/σ reads z alone), the chart's linearity, the
// stage batch, the angles (their indices are the system's: t is appended after its y), and the Jacobian J_τ = J/σ − ẇ (∇σ)ᵀ/σ² (∇σ through the chart: the identity chart
// here).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <cstddef>
#include <type_traits>
#include <utility>

#include "birkhoff_cart/core/integrators/autodiff.h"
#include "birkhoff_cart/core/integrators/birkhoffian_system.h"
#include "birkhoff_cart/core/integrators/system_traits.h"

namespace birkhoff_cart {

template <class System>
class TimeTransformedSystem {
  static_assert(system_traits::kDarbouxChartIsIdentity<System>,
                "the time transformation works in the identity chart (the autonomous form)");

 public:
  static constexpr int kDimension = System::kDimension;
  static constexpr int kPassiveDimension = System::kPassiveDimension + 1;
  static constexpr int kTimeIndex = System::kPassiveDimension;  ///< t among the passive coordinates
  static constexpr unsigned kCyclicMask = system_traits::kCyclicMask<System>;
  static constexpr int kPassiveCouplingDepth = system_traits::kPassiveCouplingDepth<System>;
  static constexpr bool kDarbouxChartIsLinear = system_traits::kDarbouxChartIsLinear<System>;
  static constexpr bool kDarbouxChartIsIdentity = true;
  static constexpr auto kAngleCoordinates = system_traits::kAngleCoordinates<System>;
  template <class S>
  using Vector = Eigen::Matrix<S, kDimension, 1>;
  template <class S>
  using Passive = Eigen::Matrix<S, kPassiveDimension, 1>;
  template <class S>
  using BasePassive = Eigen::Matrix<S, System::kPassiveDimension, 1>;

  /// `system` must outlive this; `load_time` [s] is the time the loads are read at (they do not
  /// depend on it); `stiff_density_squared` [1/s²] a constant added to σ² (a stiff load's natural
  /// frequency squared, which the steps must resolve however slowly the motion turns).
  TimeTransformedSystem(const System& system, double load_time, double stiff_density_squared = 0.0)
      : system_(&system), load_time_(load_time), stiff_density_squared_(stiff_density_squared) {}
  const System& base() const { return *system_; }
  /// The base system's periodicity of angle k (system_traits::periodic_angles).
  bool angle_is_periodic(std::size_t angle) const {
    return (system_traits::periodic_angles(*system_) >> angle) & 1u;
  }

  /// σ(z) = √(σ_system(z)² + σ_stiff²) [1/s] (eq. (B.44)).
  template <class S>
  S step_density(const Vector<S>& z) const {
    if (stiff_density_squared_ == 0.0) return system_traits::step_density(*system_, z);
    return with_stiff_density(system_traits::step_density(*system_, z));
  }

  /// σ at the stages z[j] (step_density stage by stage, bit for bit), in one call where the system
  /// batches its own (step_density_stages: one vector call for the stages' sin χ on the cart).
  template <std::size_t Count>
  void step_density_stages(const std::array<Vector<double>, Count>& z, std::array<double, Count>& densities) const {
    if constexpr (kSystemHasStepDensityStages<Count>) {
      system_->step_density_stages(z, densities);
      if (stiff_density_squared_ != 0.0) {
        for (std::size_t j = 0; j < Count; ++j) densities[j] = with_stiff_density(densities[j]);
      }
    } else {
      for (std::size_t j = 0; j < Count; ++j) densities[j] = step_density(z[j]);
    }
  }

  template <class S>
  Vector<S> to_darboux(const Vector<S>& z, const S& /*tau*/) const {
    return z;
  }
  template <class S>
  Vector<S> from_darboux(const Vector<S>& w, const S& /*tau*/) const {
    return w;
  }

  /// dw/dτ = ẇ/σ (B.41).
  template <class S>
  Vector<S> darboux_rates(const Vector<S>& w, const S& /*tau*/) const {
    const S t(load_time_);
    return system_->darboux_rates(w, t) / step_density(w);
  }

  /// dw/dτ and (g/σ, 1/σ) at one point from one σ and the base system's shared evaluation, where it
  /// has one (bit for bit darboux_rates and passive_rates).
  template <class Base = System, class = std::enable_if_t<system_traits::kHasDarbouxAndPassiveRates<Base>>>
  void darboux_and_passive_rates(const Vector<double>& w, const Passive<double>& y, double /*tau*/,
                                 Vector<double>& rate, Passive<double>& passive) const {
    Vector<double> base_rate;
    BasePassive<double> base_passive;
    system_->darboux_and_passive_rates(w, BasePassive<double>(y.template head<System::kPassiveDimension>()), load_time_,
                                       base_rate, base_passive);
    const double density = step_density(w);
    rate = base_rate / density;
    passive = in_fictive_time(base_passive, 1.0 / density);
  }

  /// The stages' dw/dτ in one call where the system batches its stage rates.
  template <std::size_t Count, class Base = System,
            class = std::enable_if_t<system_traits::kHasStageRates<Base, static_cast<int>(Count)>>>
  void darboux_rates_stages(const std::array<Vector<double>, Count>& w, const std::array<double, Count>& /*tau*/,
                            std::array<Vector<double>, Count>& rates) const {
    std::array<double, Count> times;
    times.fill(load_time_);
    system_->darboux_rates_stages(w, times, rates);
    std::array<double, Count> densities;
    step_density_stages(w, densities);
    for (std::size_t j = 0; j < Count; ++j) rates[j] /= densities[j];
  }

  /// J_τ = ∂(ẇ/σ)/∂w = J/σ − ẇ (∇σ)ᵀ/σ².
  Eigen::Matrix<double, kDimension, kDimension> darboux_jacobian(const Vector<double>& w, double /*tau*/) const {
    using JetN = Eigen::AutoDiffScalar<Eigen::Matrix<double, kDimension, 1, Eigen::DontAlign>>;
    Vector<JetN> w_jet;
    for (int k = 0; k < kDimension; ++k) {
      w_jet(k).value() = w(k);
      w_jet(k).derivatives() = Eigen::Matrix<double, kDimension, 1, Eigen::DontAlign>::Unit(k);
    }
    const JetN sigma = step_density(w_jet);
    const Eigen::Matrix<double, kDimension, kDimension> jacobian =
        system_traits::darboux_jacobian(*system_, w, load_time_);
    const Vector<double> rate = system_->darboux_rates(w, load_time_);
    const double s = sigma.value();
    return jacobian / s - rate * sigma.derivatives().transpose() / (s * s);
  }

  /// (g/σ, 1/σ): the passive rates in fictive time, time last.
  template <class S>
  Passive<S> passive_rates(const Vector<S>& z, const Passive<S>& y, const S& /*tau*/) const {
    const S t(load_time_);
    return in_fictive_time(
        passive_coordinate_rates(*system_, z, BasePassive<S>(y.template head<System::kPassiveDimension>()), t),
        S(S(1.0) / step_density(z)));
  }

  /// passive_rates at the stages in one call where the base system batches its own (bit for bit
  /// passive_rates stage by stage).
  template <std::size_t Count, class Base = System,
            class = std::enable_if_t<system_traits::kHasPassiveStageRates<Base, static_cast<int>(Count)>>>
  void passive_rates_stages(const std::array<Vector<double>, Count>& z, const std::array<Passive<double>, Count>& y,
                            const std::array<double, Count>& /*tau*/, std::array<Passive<double>, Count>& rates) const {
    std::array<BasePassive<double>, Count> base_y;
    std::array<BasePassive<double>, Count> base_rates;
    std::array<double, Count> times;
    times.fill(load_time_);
    for (std::size_t j = 0; j < Count; ++j) base_y[j] = y[j].template head<System::kPassiveDimension>();
    system_->passive_rates_stages(z, base_y, times, base_rates);
    std::array<double, Count> densities;
    step_density_stages(z, densities);
    for (std::size_t j = 0; j < Count; ++j) rates[j] = in_fictive_time(base_rates[j], 1.0 / densities[j]);
  }

  /// passive_coupling_rates at the stages in one call (as passive_rates_stages).
  template <std::size_t Count, class Base = System,
            class = std::enable_if_t<system_traits::kHasPassiveStageRates<Base, static_cast<int>(Count)>>>
  void passive_coupling_rates_stages(const std::array<Vector<double>, Count>& z, const std::array<double, Count>& /*tau*/,
                                     std::array<Passive<double>, Count>& rates) const {
    std::array<BasePassive<double>, Count> base_rates;
    std::array<double, Count> times;
    times.fill(load_time_);
    system_->passive_coupling_rates_stages(z, times, base_rates);
    std::array<double, Count> densities;
    step_density_stages(z, densities);
    for (std::size_t j = 0; j < Count; ++j) rates[j] = in_fictive_time(base_rates[j], 1.0 / densities[j]);
  }

  /// The passive rates g reads, alone (1/σ and the base system's, scaled).
  template <class S, class Base = System, class = std::enable_if_t<system_traits::kHasPassiveCouplingRates<Base>>>
  Passive<S> passive_coupling_rates(const Vector<S>& z, const S& /*tau*/) const {
    const S t(load_time_);
    return in_fictive_time(BasePassive<S>(system_->passive_coupling_rates(z, t)), S(S(1.0) / step_density(z)));
  }

 private:
  /// √(σ_system² + σ_stiff²) [1/s] from σ_system (eq. (B.44)).
  template <class S>
  S with_stiff_density(const S& base) const {
    using std::sqrt;
    return sqrt(base * base + S(stiff_density_squared_));
  }

  /// (g/σ, 1/σ) from g and 1/σ [s]: the passive rates in fictive time, time last (every passive
  /// rate above goes through here).
  template <class S>
  static Passive<S> in_fictive_time(const BasePassive<S>& rates, const S& inverse_density) {
    Passive<S> rate;
    rate.template head<System::kPassiveDimension>() = rates * inverse_density;
    rate(kTimeIndex) = inverse_density;
    return rate;
  }

  template <std::size_t Count, class = void>
  struct SystemStepDensityStages : std::false_type {};
  template <std::size_t Count>
  struct SystemStepDensityStages<Count, std::void_t<decltype(std::declval<const System&>().step_density_stages(
                                            std::declval<const std::array<Vector<double>, Count>&>(),
                                            std::declval<std::array<double, Count>&>()))>> : std::true_type {};
  /// The system gives σ at Count stages in one call.
  template <std::size_t Count>
  static constexpr bool kSystemHasStepDensityStages = SystemStepDensityStages<Count>::value;

  const System* system_;
  double load_time_;               ///< [s]
  double stiff_density_squared_;   ///< [1/s²]
};

}  // namespace birkhoff_cart
