// clientPublish without I/O: a client's channel advertisements (only <node>/command_in, schema
// rbsim_msgs/msg/Command, encoding cdr or json, at most kMaxClientChannels) and its messageData
// frames on them, handed over as data (the server decodes and submits them).
#include <algorithm>

#include "protocol_util.hpp"

namespace rbsim::foxglove::detail {

namespace {
bool as_u32(const nlohmann::json& j, std::uint32_t& out) {
  if (!j.is_number_integer()) return false;
  if (j.is_number_unsigned() ? j.get<std::uint64_t>() > UINT32_MAX
                             : (j.get<std::int64_t>() < 0 || j.get<std::int64_t>() > UINT32_MAX)) {
    return false;
  }
  out = static_cast<std::uint32_t>(j.get<std::uint64_t>());
  return true;
}
std::string string_member(const nlohmann::json& object, const char* key) {
  const auto it = object.find(key);
  return it != object.end() && it->is_string() ? it->get<std::string>() : std::string();
}
}  // namespace

void PublishOps::advertise(ClientProtocol& p, const nlohmann::json& j, Problems& problems) {
  const auto list = j.find("channels");
  if (list == j.end() || !list->is_array()) {
    problems.add("advertise: \"channels\" must be an array");
    return;
  }
  for (const nlohmann::json& c : *list) {
    std::uint32_t id = 0;
    const auto id_it = c.is_object() ? c.find("id") : c.end();
    if (!c.is_object() || id_it == c.end() || !as_u32(*id_it, id)) {
      problems.add("advertise: entry " + shown(c) + " needs an integer \"id\" in [0, 2^32)");
      continue;
    }
    const std::string topic = string_member(c, "topic");
    const std::string encoding = string_member(c, "encoding");
    const std::string schema = string_member(c, "schemaName");
    const std::string which = "advertise: channel " + std::to_string(id) + ": ";
    if (std::any_of(p.client_channels_.begin(), p.client_channels_.end(),
                    [&](const auto& k) { return k.id == id; })) {
      problems.add(which + "id already advertised");
    } else if (topic != p.publish_topic_) {
      problems.add(which + "topic " + shown(c.value("topic", nlohmann::json())) +
                   " refused: this server takes " + p.publish_topic_ + " only");
    } else if (schema != kCommandInSchema) {
      problems.add(which + "schemaName " + shown(c.value("schemaName", nlohmann::json())) +
                   " refused: " + p.publish_topic_ + " takes " + std::string(kCommandInSchema));
    } else if (std::find(std::begin(kClientPublishEncodings), std::end(kClientPublishEncodings), encoding) ==
               std::end(kClientPublishEncodings)) {
      problems.add(which + "encoding " + shown(c.value("encoding", nlohmann::json())) +
                   " refused: this server takes cdr or json");
    } else if (p.client_channels_.size() >= kMaxClientChannels) {
      problems.add(which + "refused: at most " + std::to_string(kMaxClientChannels) +
                   " client channels at a time");
    } else {
      p.client_channels_.push_back({id, encoding});
    }
  }
}

void PublishOps::unadvertise(ClientProtocol& p, const nlohmann::json& j, Problems& problems) {
  const auto ids = j.find("channelIds");
  if (ids == j.end() || !ids->is_array()) {
    problems.add("unadvertise: \"channelIds\" must be an array");
    return;
  }
  for (const nlohmann::json& v : *ids) {
    std::uint32_t id = 0;
    if (!as_u32(v, id)) {
      problems.add("unadvertise: " + shown(v) + " is not a channel id");
      continue;
    }
    const auto it = std::find_if(p.client_channels_.begin(), p.client_channels_.end(),
                                 [&](const auto& k) { return k.id == id; });
    if (it == p.client_channels_.end()) {
      problems.add("unadvertise: unknown client channel " + std::to_string(id));
      continue;
    }
    p.client_channels_.erase(it);
  }
}

void PublishOps::message(ClientProtocol& p, std::string_view frame, ClientProtocol::Outcome& out) {
  const auto error = [&](const std::string& m) { out.replies.push_back(status_json(StatusLevel::Error, m)); };
  if (frame.size() < kClientMessageHeader) {
    error("client message of " + std::to_string(frame.size()) + " bytes refused: its header alone is " +
          std::to_string(kClientMessageHeader) + " bytes");
    return;
  }
  std::uint32_t id = 0;
  for (int i = 4; i >= 1; --i)
    id = (id << 8) | static_cast<unsigned char>(frame[static_cast<std::size_t>(i)]);
  const auto it = std::find_if(p.client_channels_.begin(), p.client_channels_.end(),
                               [&](const auto& k) { return k.id == id; });
  if (it == p.client_channels_.end()) {
    error("client message on unknown channel " + std::to_string(id) + " (advertise it first)");
    return;
  }
  if (frame.size() > kMaxClientFrame) {
    error("client message of " + std::to_string(frame.size()) + " bytes refused: the limit is " +
          std::to_string(kMaxClientFrame));
    return;
  }
  out.published = ClientMessage{id, it->encoding, std::string(frame.substr(kClientMessageHeader))};
}

}  // namespace rbsim::foxglove::detail
