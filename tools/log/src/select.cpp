// Topics and times of the log tools (select.hpp).
#include "select.hpp"

#include <cmath>
#include <set>

namespace rbsim::log::detail {

std::optional<mcap::Timestamp> to_ns(std::optional<double> seconds) {
  if (!seconds) return std::nullopt;
  if (!(*seconds > 0.0)) return mcap::Timestamp{0};
  const double ns = std::round(*seconds * 1e9);
  if (ns >= 1.8e19) return mcap::kMaxTime;
  return static_cast<mcap::Timestamp>(ns);
}

Result<std::vector<std::string>> choose_topics(const Recording& recording,
                                               const std::vector<std::string>& requested) {
  std::set<std::string> known;
  for (const RecordedChannel& c : recording.channels()) known.insert(c.channel->topic);
  std::set<std::string> chosen;
  for (const std::string& name : requested) {
    if (name.empty()) continue;
    bool found = false;
    for (const std::string& topic : known) {
      if (msgs::names_topic(name, topic)) {
        chosen.insert(topic);
        found = true;
      }
    }
    if (!found) {
      std::string list;
      for (const std::string& topic : known) list += (list.empty() ? "" : ", ") + topic;
      return Error{recording.path() + ": no topic " + name + " (topics: " + (list.empty() ? "none" : list) +
                   ")"};
    }
  }
  return std::vector<std::string>(chosen.begin(), chosen.end());
}

}  // namespace rbsim::log::detail
