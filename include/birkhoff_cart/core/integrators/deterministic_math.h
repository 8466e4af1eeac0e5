// The elementary functions of the right-hand sides, with the same bits on every x86-64 CPU.
//
// glibc's libm picks its code for sin, cos, exp, log, pow, tan at run time by the CPU's features
// (FMA or not), and its results differ between those variants in the last bit now and then; an
// adaptive run or a chaotic scene turns one such bit into another step count. These functions come
// from SLEEF's deterministic scalar code instead (Sleef_cinz_*d1_u35purec for sin, cos and tanh,
// within 3.5 ulp; Sleef_cinz_*d1_u10purec for the others, within 1 ulp: pure C, no FMA), which
// computes the same bits whatever the CPU; the vector stage path (vector_math.h) calls SLEEF's AVX
// function of the same family, bit-identical to these. sin and cos answer a repeated argument from
// the last one they computed on the thread (the same bits; a right-hand side asks for sin χ and
// cos χ several times). docs/developing.md, "Figures
// that hold on every machine".
//
// Use: `using deterministic::sin;` where `using std::sin;` would stand, then unqualified sin(x) for
// x of type double, long double (sin, cos, exp: glibc's x87 software, the same on every x86-64) or
// an Eigen AutoDiffScalar over a dense derivative vector (value and derivative from these functions).
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>

#include <Eigen/Core>
#include <unsupported/Eigen/AutoDiff>

namespace birkhoff_cart {
namespace deterministic {

/// The bits of x, for memos keyed on an argument bit for bit [-].
inline std::uint64_t bits_of(double x) {
  std::uint64_t bits;
  std::memcpy(&bits, &x, sizeof bits);
  return bits;
}

double sin(double angle);   ///< [rad → -]
double cos(double angle);   ///< [rad → -]
double tan(double angle);   ///< [rad → -]
double tanh(double x);      ///< [-]
double exp(double x);       ///< [-]
double log(double x);       ///< [-], x > 0
double pow(double x, double exponent);  ///< [-]
/// {pow(x[0], exponent[0]), pow(x[1], exponent[1])} bit for bit, in one call of SLEEF's two-lane
/// SSE2 function of the same family (baseline x86-64: the same code on every CPU), which costs
/// about what one scalar call does (~510 instructions against ~580; a step control's two powers a
/// step). [-]
std::array<double, 2> pow_pair(const std::array<double, 2>& x, const std::array<double, 2>& exponent);

inline long double sin(long double angle) { return std::sin(angle); }
inline long double cos(long double angle) { return std::cos(angle); }
inline long double exp(long double x) { return std::exp(x); }

/// Forward-mode AD (autodiff.h): sin, cos and exp of the value from the functions above, the derivative
/// by the chain rule. More specialized than Eigen's own overloads, so overload resolution picks
/// these for every jet whose derivatives are a column vector (Jet<N>, newton.h's JacobianJet<N>,
/// jets of jets).
template <class Scalar, int Rows, int Options, int MaxRows>
Eigen::AutoDiffScalar<Eigen::Matrix<Scalar, Rows, 1, Options, MaxRows, 1>> sin(
    const Eigen::AutoDiffScalar<Eigen::Matrix<Scalar, Rows, 1, Options, MaxRows, 1>>& angle) {
  return {sin(angle.value()), cos(angle.value()) * angle.derivatives()};
}
template <class Scalar, int Rows, int Options, int MaxRows>
Eigen::AutoDiffScalar<Eigen::Matrix<Scalar, Rows, 1, Options, MaxRows, 1>> cos(
    const Eigen::AutoDiffScalar<Eigen::Matrix<Scalar, Rows, 1, Options, MaxRows, 1>>& angle) {
  return {cos(angle.value()), -sin(angle.value()) * angle.derivatives()};
}
template <class Scalar, int Rows, int Options, int MaxRows>
Eigen::AutoDiffScalar<Eigen::Matrix<Scalar, Rows, 1, Options, MaxRows, 1>> exp(
    const Eigen::AutoDiffScalar<Eigen::Matrix<Scalar, Rows, 1, Options, MaxRows, 1>>& x) {
  const Scalar value = exp(x.value());
  return {value, value * x.derivatives()};
}
/// A jet expression (a + b of jets, …) would otherwise go to Eigen's overload and std::: ambiguous
/// with Eigen's on purpose, so that the build stops there; name the jet (`const S y = a + b;`) first.
template <class Derivatives>
void sin(const Eigen::AutoDiffScalar<Derivatives>&) = delete;
template <class Derivatives>
void cos(const Eigen::AutoDiffScalar<Derivatives>&) = delete;
template <class Derivatives>
void exp(const Eigen::AutoDiffScalar<Derivatives>&) = delete;

}  // namespace deterministic
}  // namespace birkhoff_cart
