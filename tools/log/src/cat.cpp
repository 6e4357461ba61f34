// rbsim log cat: messages as JSON lines.
#include "rbsim/cat.hpp"

#include <cmath>
#include <map>
#include <set>

#include "rbsim/msgs.hpp"
#include "rbsim/recording.hpp"

namespace rbsim::log {

namespace {

std::optional<mcap::Timestamp> to_ns(std::optional<double> seconds) {
  if (!seconds) return std::nullopt;
  if (!(*seconds > 0.0)) return mcap::Timestamp{0};
  const double ns = std::round(*seconds * 1e9);
  if (ns >= 1.8e19) return mcap::kMaxTime;
  return static_cast<mcap::Timestamp>(ns);
}

struct ChannelDecoder {
  std::optional<msgs::MessageDecoder> decoder;  // empty: not decodable, data is null
};

}  // namespace

Status cat(const std::string& path, const CatOptions& options,
           const std::function<void(std::string_view line)>& on_line) {
  auto opened = Recording::open(path, raw_options());  // every topic as recorded, whatever its type
  if (!opened) return opened.error();
  Recording& recording = *opened.value();

  MessageFilter filter;
  if (const auto start = to_ns(options.start)) filter.start = *start;
  if (const auto end = to_ns(options.end)) filter.end = *end;
  if (!options.topics.empty()) {
    std::set<std::string> known;
    for (const RecordedChannel& c : recording.channels()) known.insert(c.channel->topic);
    std::set<std::string> chosen;
    for (const std::string& requested : options.topics) {
      bool found = false;
      for (const std::string& topic : known) {
        if (msgs::names_topic(requested, topic)) {
          chosen.insert(topic);
          found = true;
        }
      }
      if (!found) {
        std::string list;
        for (const std::string& topic : known) list += (list.empty() ? "" : ", ") + topic;
        return Error{path + ": no topic " + requested + " (topics: " + (list.empty() ? "none" : list) + ")"};
      }
    }
    filter.topics.assign(chosen.begin(), chosen.end());
  }

  std::map<std::uint16_t, ChannelDecoder> decoders;
  std::string line;
  Status failure = Ok{};
  const Status read = recording.read_messages(filter, [&](const RecordedMessage& rm) -> bool {
    const mcap::Message& m = *rm.message;
    const mcap::Schema* schema = rm.channel->schema;
    auto [it, fresh] = decoders.try_emplace(m.channel_id);
    if (fresh && schema != nullptr && schema->encoding == "ros2msg" &&
        rm.channel->channel->message_encoding == "cdr") {
      auto decoder = msgs::MessageDecoder::create(schema->name, rm.channel->schema_text());
      if (!decoder) {
        failure = Error{path + ": schema " + schema->name + ": " + decoder.error().message};
        return false;
      }
      it->second.decoder = std::move(decoder.value());
    }
    line.clear();
    line += "{\"topic\":";
    msgs::append_json_string(line, rm.topic());
    line += ",\"sequence\":" + std::to_string(m.sequence);
    line += ",\"log_time\":" + std::to_string(m.log_time);
    line += ",\"publish_time\":" + std::to_string(m.publish_time);
    line += ",\"data\":";
    if (it->second.decoder) {
      if (Status st = it->second.decoder->to_json(rm.cdr(), line); !st) {
        failure = Error{path + ": " + rm.topic() + " message at log time " + std::to_string(m.log_time) +
                        " ns: " + st.error().message};
        return false;
      }
    } else {
      line += "null";
    }
    line += '}';
    on_line(line);
    return true;
  });
  if (!read) return read;
  return failure;
}

}  // namespace rbsim::log
