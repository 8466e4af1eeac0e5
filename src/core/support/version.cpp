#include "birkhoff_cart/core/support/version.h"

#include <cstdio>
#include <cstring>

#ifndef BIRKHOFF_CART_VERSION
#error "BIRKHOFF_CART_VERSION must be defined by the build (CMakeLists.txt, from package.xml)"
#endif

namespace birkhoff_cart {

const char* package_version() { return BIRKHOFF_CART_VERSION; }

bool print_version_if_asked(int argc, char** argv, const char* program) {
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--version") == 0) {
      std::printf("%s (birkhoff_cart) %s\n", program, package_version());
      return true;
    }
  }
  return false;
}

}  // namespace birkhoff_cart
