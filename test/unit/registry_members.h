// The registry's members as gtest type lists (integrator_members.h), for the typed suites that run
// over every member's generic stepper: integrator_contract_test and k_symplectic_test. A new member
// of the registry is in each of them without a change here.
// Header-only: every test/unit/*.cpp is its own executable.
#pragma once

#include <gtest/gtest.h>

#include <string>
#include <tuple>
#include <type_traits>
#include <vector>

#include "birkhoff_cart/core/integrators/integrator_members.h"

namespace birkhoff_cart_test {

namespace registry_members_detail {
template <class List>
struct GtestTypes;
template <class... Steppers>
struct GtestTypes<birkhoff_cart::StepperList<Steppers...>> {
  using type = ::testing::Types<Steppers...>;
};

/// The steppers of `List` for which Keep<Stepper>::value holds, in order.
template <template <class> class Keep, class List>
struct Filter;
template <template <class> class Keep, class... Steppers>
struct Filter<Keep, birkhoff_cart::StepperList<Steppers...>> {
  template <class Stepper>
  using Kept = std::conditional_t<Keep<Stepper>::value, std::tuple<Stepper>, std::tuple<>>;
  template <class Tuple>
  struct ToList;
  template <class... Kept>
  struct ToList<std::tuple<Kept...>> {
    using type = birkhoff_cart::StepperList<Kept...>;
  };
  using type = typename ToList<decltype(std::tuple_cat(std::declval<Kept<Steppers>>()...))>::type;
};

template <class List>
struct Names;
template <class... Steppers>
struct Names<birkhoff_cart::StepperList<Steppers...>> {
  static std::vector<std::string> get() { return {Steppers::name()...}; }
};
}  // namespace registry_members_detail

/// Does the member step in the Darboux chart (a Birkhoffian collocation member or composition)?
template <class Stepper>
struct IsBirkhoffianMember : std::integral_constant<bool, birkhoff_cart::is_birkhoffian(birkhoff_cart::member_kind<Stepper>())> {};

/// The Birkhoffian members (K(z,t)-symplectic where Λ = 0), in the registry's order.
using BirkhoffianMemberTypes =
    typename registry_members_detail::Filter<IsBirkhoffianMember, birkhoff_cart::IntegratorMemberTypes>::type;

/// testing::Types of every member's stepper, and of the Birkhoffian ones.
using RegistrySteppers = typename registry_members_detail::GtestTypes<birkhoff_cart::IntegratorMemberTypes>::type;
using BirkhoffianSteppers = typename registry_members_detail::GtestTypes<BirkhoffianMemberTypes>::type;

/// The names of a list's steppers, in order.
template <class List>
std::vector<std::string> stepper_names() {
  return registry_members_detail::Names<List>::get();
}

/// The member's generic stepper with the registry's default settings (IntegratorSettings{}).
template <class Stepper>
Stepper default_stepper() {
  return birkhoff_cart::configured_stepper<Stepper>(birkhoff_cart::IntegratorSettings{});
}

/// gtest's name of a typed test's case: the member's name ("IntegratorContract/birkhoff_gauss4.…").
struct StepperNames {
  template <class Stepper>
  static std::string GetName(int) {
    return Stepper::name();
  }
};

}  // namespace birkhoff_cart_test
