// Seconds to nanoseconds (one rounding rule, refused or clamped out of range) and the monotonic
// clock (rbsim/time.hpp).
#include "rbsim/time.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <limits>

namespace rbsim {
namespace {

constexpr std::int64_t kMax = std::numeric_limits<std::int64_t>::max();

TEST(RbsimTime, SecondsRoundToTheNearestNanosecond) {
  EXPECT_EQ(seconds_to_ns(0.0).value(), 0);
  EXPECT_EQ(seconds_to_ns(1.5).value(), 1'500'000'000);
  EXPECT_EQ(seconds_to_ns(0.1).value(), 100'000'000);  // 0.1 * 1e9 is 100000000.00000001
  EXPECT_EQ(seconds_to_ns(1e-9 * 0.4).value(), 0);     // below half a nanosecond: down
  EXPECT_EQ(seconds_to_ns(1e-9 * 0.6).value(), 1);     // above: up, not truncated
  EXPECT_EQ(seconds_to_ns(2.9999999996).value(), 3'000'000'000);
  EXPECT_EQ(seconds_to_ns(9223372036.0).value(), 9'223'372'036'000'000'000);
  EXPECT_EQ(seconds_to_ns_clamped(2.9999999996), 3'000'000'000);
  EXPECT_EQ(seconds_to_ns_clamped(0.01 * 3), 30'000'000);  // a step's time: round(step * dt * 1e9)
}

TEST(RbsimTime, NoDurationIsRefusedWithAClearError) {
  for (const double bad : {-1.5, -1e-300, std::nan(""), std::numeric_limits<double>::infinity(),
                           -std::numeric_limits<double>::infinity(), 1e10, 1e300}) {
    const Result<std::int64_t> ns = seconds_to_ns(bad);
    ASSERT_FALSE(ns.ok()) << bad;
    EXPECT_EQ(ns.error().code, ErrorCode::InvalidArgument);
    EXPECT_NE(ns.error().message.find("s is not a duration: seconds must be finite, at least 0 and at most "
                                      "9223372036"),
              std::string::npos)
        << ns.error().message;
  }
  EXPECT_EQ(seconds_to_ns(-1.5).error().message,
            "-1.5 s is not a duration: seconds must be finite, at least 0 and at most 9223372036");
}

TEST(RbsimTime, ClampedGivesZeroBelowAndTheMaximumAbove) {
  EXPECT_EQ(seconds_to_ns_clamped(-1.5), 0);
  EXPECT_EQ(seconds_to_ns_clamped(std::nan("")), 0);
  EXPECT_EQ(seconds_to_ns_clamped(-std::numeric_limits<double>::infinity()), 0);
  EXPECT_EQ(seconds_to_ns_clamped(std::numeric_limits<double>::infinity()), kMax);
  EXPECT_EQ(seconds_to_ns_clamped(1e10), kMax);
  EXPECT_EQ(seconds_to_ns_clamped(9223372036.0), 9'223'372'036'000'000'000);
}

TEST(RbsimTime, TheMonotonicClockNeverGoesBack) {
  std::int64_t last = monotonic_ns();
  EXPECT_GT(last, 0);
  for (int i = 0; i < 1000; ++i) {
    const std::int64_t now = monotonic_ns();
    ASSERT_GE(now, last);
    last = now;
  }
}

// The wall clock is the system clock's epoch count (what stamps say): bracketed by two readings of
// std::chrono::system_clock, an independent reader of the same clock.
TEST(RbsimTime, WallNsIsTheSystemClockSinceTheEpoch) {
  const auto system_ns = [] {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(
               std::chrono::system_clock::now().time_since_epoch())
        .count();
  };
  const std::int64_t before = system_ns();
  const std::int64_t wall = wall_ns();
  const std::int64_t after = system_ns();
  EXPECT_LE(before, wall);
  EXPECT_LE(wall, after);
  EXPECT_GT(wall, std::int64_t{1'600'000'000} * 1'000'000'000);  // after 2020: an epoch count, not uptime
}

}  // namespace
}  // namespace rbsim
