// Sleeping until a monotonic time for pacing (node, replay); the clock is base's monotonic_ns().
#pragma once
#include <time.h>

#include <cstdint>

#include "rbsim/time.hpp"

namespace rbsim::node {

// Sleeps until `deadline_ns` (monotonic). A signal (Ctrl-C) ends the sleep early: callers look at
// their stop flag afterwards.
inline void sleep_until(std::int64_t deadline_ns) {
  const timespec ts{static_cast<time_t>(deadline_ns / 1'000'000'000),
                    static_cast<long>(deadline_ns % 1'000'000'000)};
  (void)clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr);
}

}  // namespace rbsim::node
