#include "rbsim/time.hpp"

#include <time.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

namespace rbsim {

namespace {
constexpr double kPastRange = 9223372036854775808.0;  // 2^63: the first ns count past INT64_MAX
}  // namespace

Result<std::int64_t> seconds_to_ns(double seconds) {
  const double ns = std::round(seconds * 1e9);
  if (!(seconds >= 0.0 && ns < kPastRange)) {  // NaN fails both comparisons
    char value[32];
    std::snprintf(value, sizeof value, "%g", seconds);
    return Error{std::string(value) +
                     " s is not a duration: seconds must be finite, at least 0 and at most " +
                     std::to_string(static_cast<std::int64_t>(kMaxSeconds)),
                 ErrorCode::InvalidArgument};
  }
  return static_cast<std::int64_t>(ns);
}

std::int64_t seconds_to_ns_clamped(double seconds) {
  const double ns = std::round(seconds * 1e9);
  if (!(ns > 0.0)) return 0;  // NaN, negative, zero
  if (ns >= kPastRange) return std::numeric_limits<std::int64_t>::max();
  return static_cast<std::int64_t>(ns);
}

std::int64_t monotonic_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

std::int64_t wall_ns() {
  timespec ts{};
  clock_gettime(CLOCK_REALTIME, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

}  // namespace rbsim
