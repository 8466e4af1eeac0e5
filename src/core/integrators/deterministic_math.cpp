// deterministic_math.h from SLEEF's pure-C, FMA-free functions (Debian: libsleef-dev): sin, cos and
// tanh within 3.5 ulp (u35, half the price of the 1-ulp u10 ones), the others within 1 ulp; two
// powers at once from the SSE2 function of the same family (the same bits as the pure-C one).
//
// A right-hand side asks for sin and cos of the same steering angle several times (the mass matrix,
// the momentum rates, each load, a jet's value and derivative): each function keeps its last
// argument and value per thread and answers a repeated argument from there. The argument is
// compared by its bits (sin(−0) is −0, sin(+0) is +0), so a cached answer is the same bits as a
// fresh one.
#include "birkhoff_cart/core/integrators/deterministic_math.h"

#include <cstdint>
#include <cstring>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <sleef.h>

namespace birkhoff_cart {
namespace deterministic {
namespace {

/// The last argument and value of one function, on this thread.
struct LastValue {
  bool valid = false;
  std::uint64_t argument_bits = 0;
  double value = 0.0;
};

template <auto function>
double remembered(double x, LastValue& last) {
  const std::uint64_t bits = bits_of(x);
  if (!last.valid || bits != last.argument_bits) {
    last.value = function(x);
    last.argument_bits = bits;
    last.valid = true;
  }
  return last.value;
}

// initial-exec: a load, not a call to __tls_get_addr per use (the library is linked, or dlopen'ed
// by Python, with static TLS to spare for these 48 bytes).
#define BIRKHOFF_CART_FAST_TLS __attribute__((tls_model("initial-exec")))
thread_local LastValue last_sin BIRKHOFF_CART_FAST_TLS;
thread_local LastValue last_cos BIRKHOFF_CART_FAST_TLS;
#undef BIRKHOFF_CART_FAST_TLS

}  // namespace

double sin(double angle) { return remembered<Sleef_cinz_sind1_u35purec>(angle, last_sin); }
double cos(double angle) { return remembered<Sleef_cinz_cosd1_u35purec>(angle, last_cos); }
double tan(double angle) { return Sleef_cinz_tand1_u10purec(angle); }
double tanh(double x) { return Sleef_cinz_tanhd1_u35purec(x); }
double exp(double x) { return Sleef_cinz_expd1_u10purec(x); }
double log(double x) { return Sleef_cinz_logd1_u10purec(x); }
double pow(double x, double exponent) { return Sleef_cinz_powd1_u10purec(x, exponent); }

std::array<double, 2> pow_pair(const std::array<double, 2>& x, const std::array<double, 2>& exponent) {
#if defined(__SSE2__)
  std::array<double, 2> result;
  _mm_storeu_pd(result.data(), Sleef_cinz_powd2_u10sse2(_mm_loadu_pd(x.data()), _mm_loadu_pd(exponent.data())));
  return result;
#else
  return {pow(x[0], exponent[0]), pow(x[1], exponent[1])};
#endif
}

}  // namespace deterministic
}  // namespace birkhoff_cart
