#include "rbsim/assert.hpp"

#include <cstdio>
#include <cstdlib>

namespace rbsim::detail {

void assertion_failed(const char* condition, const char* message, const char* file, int line) {
  std::fprintf(stderr, "%s:%d: internal error: %s (%s failed)\n", file, line, message, condition);
  std::fflush(stderr);
  std::abort();
}

}  // namespace rbsim::detail
