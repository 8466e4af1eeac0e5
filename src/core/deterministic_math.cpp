// deterministic_math.h from SLEEF's pure-C, FMA-free functions (Debian: libsleef-dev).
#include "birkhoff_cart/core/deterministic_math.h"

#include <sleef.h>

namespace birkhoff_cart {
namespace deterministic {

double sin(double angle) { return Sleef_cinz_sind1_u10purec(angle); }
double cos(double angle) { return Sleef_cinz_cosd1_u10purec(angle); }
double tan(double angle) { return Sleef_cinz_tand1_u10purec(angle); }
double tanh(double x) { return Sleef_cinz_tanhd1_u10purec(x); }
double exp(double x) { return Sleef_cinz_expd1_u10purec(x); }
double log(double x) { return Sleef_cinz_logd1_u10purec(x); }
double pow(double x, double exponent) { return Sleef_cinz_powd1_u10purec(x, exponent); }

}  // namespace deterministic
}  // namespace birkhoff_cart
