// A recording's commands (rbsim/recording.hpp): every rbsim_msgs/msg/Command, in sequence order.
#include <algorithm>
#include <string>

#include "rbsim/interfaces.hpp"
#include "rbsim/recording.hpp"

namespace rbsim::recordings {

Result<std::vector<msgs::CommandMessage>> read_commands(Recording& recording) {
  std::vector<msgs::CommandMessage> out;
  const std::string& topic = recording.topic(msgs::TopicId::Commands);
  if (topic.empty()) return out;
  Status decoded = Ok{};
  MessageFilter filter;
  filter.topics = {topic};
  Status st = recording.read_messages(filter, [&](const RecordedMessage& m) {
    msgs::CommandMessage c;
    if (Status d = msgs::decode(m.cdr(), c); !d) {
      decoded = with_context(recording.path() + ": " + topic + " message at log time " +
                                 std::to_string(m.message->log_time) + ": ",
                             d.error(), ErrorCode::Malformed);
      return false;
    }
    out.push_back(std::move(c));
    return true;
  });
  if (!st) return st.error();
  if (!decoded) return decoded.error();
  // A recorder may receive a command twice (a writer's history sent again after a reconnection):
  // one of each sequence number counts.
  std::stable_sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.seq < b.seq; });
  out.erase(std::unique(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.seq == b.seq; }),
            out.end());
  for (std::size_t i = 0; i < out.size(); ++i) {
    if (out[i].seq != i) {
      return Error{recording.path() + ": " + topic + ": command " + std::to_string(i) +
                       " is missing (the recording has " + std::to_string(out.size()) +
                       " commands, numbered up to " + std::to_string(out.back().seq) +
                       "): the recorder joined late or lost commands, so this is not the whole session",
                   ErrorCode::Malformed};
    }
  }
  return out;
}

}  // namespace rbsim::recordings
