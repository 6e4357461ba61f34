// rbsim log cat: messages as JSON lines.
#include "rbsim/cat.hpp"

#include <cmath>
#include <map>
#include <set>

#include "rbsim/mcap.hpp"
#include "rbsim/mcap_tools.hpp"
#include "rbsim/msgs.hpp"

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
  mcap::IndexedReader reader;
  if (Status st = reader.open(path); !st.ok()) return Error{path + ": " + mcap_tools::read_error(st.error())};

  mcap::ReadMessagesOptions ro;
  if (const auto start = to_ns(options.start)) ro.start_time = *start;
  if (const auto end = to_ns(options.end)) ro.end_time = *end;
  if (!options.topics.empty()) {
    std::set<std::string> known;
    for (const auto& [id, channel] : reader.channels()) known.insert(channel.topic);
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
    ro.topics.assign(chosen.begin(), chosen.end());
  }

  std::map<std::uint16_t, ChannelDecoder> decoders;
  std::string line;
  Status failure = Ok{};
  Status read = reader.read_messages(ro, [&](const mcap::MessageEntry& e) -> bool {
    const mcap::Message& m = e.message;
    auto [it, fresh] = decoders.try_emplace(m.channel_id);
    if (fresh && e.channel != nullptr && e.schema != nullptr && e.schema->encoding == "ros2msg" &&
        e.channel->message_encoding == "cdr") {
      const std::string_view text(reinterpret_cast<const char*>(e.schema->data.data()),
                                  e.schema->data.size());
      auto decoder = msgs::MessageDecoder::create(e.schema->name, text);
      if (!decoder) {
        failure = Error{path + ": schema " + e.schema->name + ": " + decoder.error().message};
        return false;
      }
      it->second.decoder = std::move(decoder.value());
    }
    line.clear();
    line += "{\"topic\":";
    msgs::append_json_string(line, e.channel != nullptr ? e.channel->topic : std::string());
    line += ",\"sequence\":" + std::to_string(m.sequence);
    line += ",\"log_time\":" + std::to_string(m.log_time);
    line += ",\"publish_time\":" + std::to_string(m.publish_time);
    line += ",\"data\":";
    if (it->second.decoder) {
      if (Status st = it->second.decoder->to_json(std::as_bytes(std::span(m.data)), line); !st) {
        failure = Error{path + ": " + (e.channel != nullptr ? e.channel->topic : "?") +
                        " message at log time " + std::to_string(m.log_time) + " ns: " + st.error().message};
        return false;
      }
    } else {
      line += "null";
    }
    line += '}';
    on_line(line);
    return true;
  });
  if (!read.ok()) return Error{path + ": " + mcap_tools::read_error(read.error())};
  return failure;
}

}  // namespace rbsim::log
