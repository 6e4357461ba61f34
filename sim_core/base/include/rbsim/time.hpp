// Seconds to nanoseconds, and the clocks: the one conversion of a time or duration given in
// seconds (an option, a step's simulated time) to integer nanoseconds, the one clock that paces
// and times out (the node's pacer, the replay's player, the Foxglove server), and the one reading
// of wall time (stamps).
#pragma once

#include <cstdint>

#include "rbsim/status.hpp"

namespace rbsim {

// The largest number of seconds that fits in nanoseconds: INT64_MAX ns, about 292 years.
inline constexpr double kMaxSeconds = 9223372036.854775807;

// The rule: `seconds` times 1e9, rounded to the nearest integer (halves away from zero, as
// std::round). NaN, an infinity, a negative value and one past kMaxSeconds are no duration:
// seconds_to_ns() refuses them ("-1.5 s is not a duration: seconds must be finite, at least 0
// and at most 9223372036", ErrorCode::InvalidArgument), for values a user gives that nothing
// checked yet; seconds_to_ns_clamped() clamps them, for callers that checked their input or mean a
// bound (a timeout, a pacing deadline, a log-time window): NaN and negative values give 0, +inf
// and values past the range INT64_MAX.
[[nodiscard]] Result<std::int64_t> seconds_to_ns(double seconds);
std::int64_t seconds_to_ns_clamped(double seconds);

// The monotonic clock (CLOCK_MONOTONIC, the clock std::chrono::steady_clock reads) in ns since an
// unspecified start.
std::int64_t monotonic_ns();
// The wall clock (CLOCK_REALTIME, std::chrono::system_clock) in ns since the Unix epoch: what a
// log time, a /rosout stamp, a goal stamp or a service event's stamp says, never what paces.
std::int64_t wall_ns();

}  // namespace rbsim
