// Topics and times of the log tools (select.hpp).
#include "select.hpp"

#include <algorithm>
#include <limits>
#include <set>

#include "rbsim/time.hpp"

namespace rbsim::recordings::detail {

std::optional<mcap::Timestamp> to_ns(std::optional<double> seconds) {
  if (!seconds) return std::nullopt;
  const std::int64_t ns = seconds_to_ns_clamped(*seconds);
  if (ns == std::numeric_limits<std::int64_t>::max()) return mcap::kMaxTime;  // past the range: no end
  return static_cast<mcap::Timestamp>(ns);
}

Result<std::vector<std::string>> choose_topics(const Recording& recording,
                                               const std::vector<std::string>& requested) {
  if (std::all_of(requested.begin(), requested.end(), [](const std::string& n) { return n.empty(); }))
    return std::vector<std::string>{};
  std::vector<msgs::TopicCandidate> candidates;
  for (const RecordedChannel& c : recording.channels()) candidates.push_back({c.channel->topic, c.spec});
  msgs::TopicFilter filter;
  filter.topics = requested;
  Result<std::vector<std::size_t>> chosen = msgs::select_topics(filter, candidates);
  if (!chosen) return Error{recording.path() + ": " + chosen.error().message, chosen.error().code};
  std::set<std::string> names;
  for (const std::size_t i : chosen.value()) names.insert(candidates[i].name);
  return std::vector<std::string>(names.begin(), names.end());
}

}  // namespace rbsim::recordings::detail
