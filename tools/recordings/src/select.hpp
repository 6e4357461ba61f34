// Choosing a recording's topics and times from a command line's names and seconds (log cat,
// filter): one rule for every log tool.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "rbsim/recording.hpp"

namespace rbsim::recordings::detail {

// Seconds to integer nanoseconds of log time, by base's seconds_to_ns_clamped() (negative or NaN:
// 0; past INT64_MAX ns: kMaxTime).
std::optional<mcap::Timestamp> to_ns(std::optional<double> seconds);

// The recorded topics `requested` names, by msgs::select_topics() (as recorded, "/rbsim/body_states",
// by its last name part(s), "body_states", or by the suffix of its type's topic), sorted; none
// when no name is given. A name that selects no channel is msgs::unknown_topic() after the file's
// path: "run.mcap: unknown topic \"nope\" (topics: /clock, /rbsim/body_states, ...)".
Result<std::vector<std::string>> choose_topics(const Recording& recording,
                                               const std::vector<std::string>& requested);

}  // namespace rbsim::recordings::detail
