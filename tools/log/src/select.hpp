// Choosing a recording's topics and times from a command line's names and seconds (log cat,
// filter): one rule for every log tool.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "rbsim/recording.hpp"

namespace rbsim::log::detail {

// Seconds to integer nanoseconds of log time (negative: 0; past the range: kMaxTime).
std::optional<mcap::Timestamp> to_ns(std::optional<double> seconds);

// The recorded topics `requested` names, each as recorded ("/rbsim/body_states") or by its last
// name part(s) ("body_states"), sorted; a name that matches no channel is an error naming the file,
// the name and the recording's topics.
Result<std::vector<std::string>> choose_topics(const Recording& recording,
                                               const std::vector<std::string>& requested);

}  // namespace rbsim::log::detail
