// The Foxglove WebSocket protocol without I/O: what the server says, and one client's frames
// parsed into subscriptions or a status error.
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstring>

#include "protocol_util.hpp"
#include "rbsim/foxglove.hpp"

namespace rbsim::foxglove {

std::optional<std::string_view> choose_subprotocol(std::span<const std::string> offered) {
  for (const std::string& o : offered) {
    for (std::string_view ours : kSubprotocols) {
      if (o == ours) return ours;
    }
  }
  return std::nullopt;
}

std::string server_info_json(std::string_view name, std::string_view session_id, bool control,
                             bool services) {
  nlohmann::json j = {{"op", "serverInfo"},
                      {"name", std::string(name)},
                      {"capabilities", nlohmann::json::array({"time"})},
                      {"metadata", nlohmann::json::object()},
                      {"sessionId", std::string(session_id)}};
  if (control) {
    for (const char* c : {"parameters", "parametersSubscribe", "services", "clientPublish"})
      j["capabilities"].push_back(c);
  } else if (services) {
    j["capabilities"].push_back("services");
  }
  if (control || services) {
    j["supportedEncodings"] = nlohmann::json::array();
    for (std::string_view e : kServiceEncodings) j["supportedEncodings"].push_back(std::string(e));
  }
  return j.dump();
}

std::string advertise_services_json(std::span<const ServiceSpec> services) {
  nlohmann::json list = nlohmann::json::array();
  for (std::size_t i = 0; i < services.size(); ++i) {
    const ServiceSpec& s = services[i];
    const auto part = [&](const char* suffix, const std::string& schema) {
      return nlohmann::json{{"encoding", "cdr"},
                            {"schemaName", s.type + suffix},
                            {"schemaEncoding", "ros2msg"},
                            {"schema", schema}};
    };
    list.push_back({{"id", i + 1},
                    {"name", s.name},
                    {"type", s.type},
                    {"request", part("_Request", s.request_schema)},
                    {"response", part("_Response", s.response_schema)},
                    {"requestSchema", s.request_schema},
                    {"responseSchema", s.response_schema}});
  }
  return nlohmann::json{{"op", "advertiseServices"}, {"services", std::move(list)}}.dump();
}

std::string service_call_failure_json(ServiceId service, CallId call, std::string_view message) {
  return nlohmann::json{{"op", "serviceCallFailure"},
                        {"serviceId", service},
                        {"callId", call},
                        {"message", std::string(message)}}
      .dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

std::string advertise_json(std::span<const ChannelSpec> channels) {
  nlohmann::json list = nlohmann::json::array();
  for (std::size_t i = 0; i < channels.size(); ++i) {
    const ChannelSpec& c = channels[i];
    list.push_back({{"id", i + 1},
                    {"topic", c.topic},
                    {"encoding", c.encoding},
                    {"schemaName", c.schema_name},
                    {"schema", c.schema},
                    {"schemaEncoding", c.schema_encoding}});
  }
  return nlohmann::json{{"op", "advertise"}, {"channels", std::move(list)}}.dump();
}

std::string problems_status_json(std::string_view op, const std::vector<std::string>& problems) {
  if (problems.empty()) return {};
  std::string m = std::string(op) + ": ";
  for (std::size_t k = 0; k < problems.size() && k < 5; ++k) m += (k ? "; " : "") + problems[k];
  if (problems.size() > 5) m += "; and " + std::to_string(problems.size() - 5) + " more";
  return status_json(StatusLevel::Error, m);
}

std::string status_json(StatusLevel level, std::string_view message) {
  // Invalid UTF-8 (a client's bytes quoted back) is replaced, not thrown on.
  return nlohmann::json{
      {"op", "status"}, {"level", static_cast<int>(level)}, {"message", std::string(message)}}
      .dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

namespace {
void append_le(std::string& out, std::uint64_t v, int bytes) {
  for (int i = 0; i < bytes; ++i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}
}  // namespace

void append_message_data(std::string& out, SubscriptionId subscription, std::uint64_t log_time_ns,
                         std::span<const std::byte> payload) {
  out.reserve(out.size() + kMessageDataHeader + payload.size());
  out.push_back('\x01');
  append_le(out, subscription, 4);
  append_le(out, log_time_ns, 8);
  out.append(reinterpret_cast<const char*>(payload.data()), payload.size());  // no zero fill first
}

void append_time(std::string& out, std::uint64_t time_ns) {
  out.push_back('\x02');
  append_le(out, time_ns, 8);
}

void append_service_call_response(std::string& out, ServiceId service, CallId call, std::string_view encoding,
                                  std::span<const std::byte> payload) {
  out.push_back('\x03');
  append_le(out, service, 4);
  append_le(out, call, 4);
  append_le(out, encoding.size(), 4);
  out.append(encoding);
  out.append(reinterpret_cast<const char*>(payload.data()), payload.size());
}

// ---------------------------------------------------------------------------------------------
// ClientProtocol

using detail::kMaxDepth;
using detail::parameter_op;
using detail::Problems;
using detail::PublishOps;
using detail::shown;
using detail::too_deep;

namespace {

// A protocol id: a JSON integer in [0, 2^32). (An out parameter: GCC 12 misreports an
// std::optional<uint32_t> here as maybe uninitialized under -O2.)
bool as_id(const nlohmann::json& j, std::uint32_t& out) {
  if (j.is_number_unsigned()) {
    const auto v = j.get<std::uint64_t>();
    if (v > UINT32_MAX) return false;
    out = static_cast<std::uint32_t>(v);
    return true;
  }
  if (j.is_number_integer()) {
    const auto v = j.get<std::int64_t>();
    if (v < 0 || v > UINT32_MAX) return false;
    out = static_cast<std::uint32_t>(v);
    return true;
  }
  return false;
}
bool member_id(const nlohmann::json& object, const char* key, std::uint32_t& out) {
  const auto it = object.find(key);
  return it != object.end() && as_id(*it, out);
}

// The ops of the protocol this server never offers, and those it offers with a controller only.
constexpr std::string_view kUnofferedOps[] = {
    "advertise",  "unadvertise",      "subscribeConnectionGraph", "unsubscribeConnectionGraph",
    "fetchAsset", "advertiseServices"};
constexpr std::string_view kParameterOps[] = {"getParameters", "setParameters", "subscribeParameterUpdates",
                                              "unsubscribeParameterUpdates"};

std::uint32_t read_u32(std::string_view b, std::size_t at) {
  std::uint32_t v = 0;
  for (int i = 3; i >= 0; --i) v = (v << 8) | static_cast<unsigned char>(b[at + static_cast<std::size_t>(i)]);
  return v;
}
// A text frame as a JSON object with an "op" string; nullopt (and the status error in `out`) when
// it is not one.
std::optional<nlohmann::json> parse_request(std::string_view frame, ClientProtocol::Outcome& out) {
  auto error = [&](const std::string& m) { out.replies.push_back(status_json(StatusLevel::Error, m)); };
  if (frame.size() > kMaxClientFrame) {
    error("message of " + std::to_string(frame.size()) + " bytes refused: the limit is " +
          std::to_string(kMaxClientFrame));
    return std::nullopt;
  }
  if (too_deep(frame)) {
    error("malformed message: JSON nested deeper than " + std::to_string(kMaxDepth));
    return std::nullopt;
  }
  nlohmann::json j = nlohmann::json::parse(frame.begin(), frame.end(), nullptr, false);
  if (j.is_discarded()) {
    error("malformed message: not valid JSON");
    return std::nullopt;
  }
  if (!j.is_object()) {
    error("malformed message: not a JSON object");
    return std::nullopt;
  }
  const auto op_it = j.find("op");
  if (op_it == j.end() || !op_it->is_string()) {
    error("malformed message: no \"op\" string");
    return std::nullopt;
  }
  return j;
}

// subscribe: each valid entry takes effect, each invalid one is a problem. A request that is no
// array is one status error (before any problem, so the caller's flush adds nothing).
void subscribe(const nlohmann::json& j, std::vector<std::optional<SubscriptionId>>& by_channel,
               std::size_t& count, ClientProtocol::Outcome& out, Problems& problems) {
  const auto subs = j.find("subscriptions");
  if (subs == j.end() || !subs->is_array()) {
    out.replies.push_back(status_json(StatusLevel::Error, "subscribe: \"subscriptions\" must be an array"));
    return;
  }
  for (const nlohmann::json& s : *subs) {
    if (!s.is_object()) {
      problems.add("subscribe: entry " + shown(s) + " is not an object");
      continue;
    }
    std::uint32_t id = 0, ch = 0;
    if (!member_id(s, "id", id) || !member_id(s, "channelId", ch)) {
      problems.add("subscribe: entry " + shown(s) + " needs integer \"id\" and \"channelId\" in [0, 2^32)");
      continue;
    }
    if (ch == 0 || ch > by_channel.size()) {
      problems.add("subscribe: unknown channel " + std::to_string(ch));
      continue;
    }
    if (by_channel[ch - 1]) {
      problems.add("subscribe: already subscribed to channel " + std::to_string(ch) + " (subscription " +
                   std::to_string(*by_channel[ch - 1]) + ")");
      continue;
    }
    if (std::find(by_channel.begin(), by_channel.end(), std::optional<SubscriptionId>(id)) !=
        by_channel.end()) {
      problems.add("subscribe: subscription id " + std::to_string(id) + " is already in use");
      continue;
    }
    by_channel[ch - 1] = id;
    ++count;
    out.subscribed.push_back({id, ch});
  }
}

// unsubscribe: as subscribe, each known id ended, each other one a problem.
void unsubscribe(const nlohmann::json& j, std::vector<std::optional<SubscriptionId>>& by_channel,
                 std::size_t& count, ClientProtocol::Outcome& out, Problems& problems) {
  const auto ids = j.find("subscriptionIds");
  if (ids == j.end() || !ids->is_array()) {
    out.replies.push_back(
        status_json(StatusLevel::Error, "unsubscribe: \"subscriptionIds\" must be an array"));
    return;
  }
  for (const nlohmann::json& v : *ids) {
    std::uint32_t id = 0;
    if (!as_id(v, id)) {
      problems.add("unsubscribe: " + shown(v) + " is not a subscription id");
      continue;
    }
    const auto it = std::find(by_channel.begin(), by_channel.end(), std::optional<SubscriptionId>(id));
    if (it == by_channel.end()) {
      problems.add("unsubscribe: unknown subscription " + std::to_string(id));
      continue;
    }
    it->reset();
    --count;
    out.unsubscribed.push_back({id, static_cast<ChannelId>(it - by_channel.begin() + 1)});
  }
}
}  // namespace

ClientProtocol::ClientProtocol(std::uint32_t channel_count, bool parameters, std::uint32_t service_count)
    : by_channel_(channel_count), parameters_(parameters), service_count_(service_count) {}

std::optional<SubscriptionId> ClientProtocol::subscription(ChannelId channel) const {
  if (channel == 0 || channel > by_channel_.size()) return std::nullopt;
  return by_channel_[channel - 1];
}

void ClientProtocol::handle_binary(std::string_view frame, Outcome& out) {
  out.clear();
  const auto error = [&](const std::string& m) { out.replies.push_back(status_json(StatusLevel::Error, m)); };
  const std::string size = std::to_string(frame.size()) + " bytes";
  if (!publish_topic_.empty() && !frame.empty() && frame[0] == '\x01') {
    PublishOps::message(*this, frame, out);
    return;
  }
  if (service_count_ == 0 || frame.empty() || frame[0] != '\x02') {
    error("binary message of " + size + " refused: this server accepts " +
          (service_count_ == 0 ? std::string("no client publishing or service calls")
           : publish_topic_.empty()
               ? std::string("service call requests (opcode 0x02) only, no client publishing")
               : std::string("client messages (opcode 0x01) and service call requests "
                             "(opcode 0x02) only")));
    return;
  }
  if (frame.size() < kServiceCallHeader) {
    error("service call request of " + size + " refused: its header alone is " +
          std::to_string(kServiceCallHeader) + " bytes");
    return;
  }
  ServiceCall c;
  c.service = read_u32(frame, 1);
  c.call = read_u32(frame, 5);
  const std::uint32_t encoding_size = read_u32(frame, 9);
  const auto fail = [&](const std::string& m) {
    out.replies.push_back(service_call_failure_json(c.service, c.call, m));
  };
  if (frame.size() > kMaxClientFrame) {
    fail("request of " + size + " refused: the limit is " + std::to_string(kMaxClientFrame));
  } else if (c.service == 0 || c.service > service_count_) {
    fail("unknown service " + std::to_string(c.service) + " (services are 1.." +
         std::to_string(service_count_) + ")");
  } else if (encoding_size > frame.size() - kServiceCallHeader) {
    fail("encoding length " + std::to_string(encoding_size) + " runs past the " + size + " message");
  } else {
    c.encoding = std::string(frame.substr(kServiceCallHeader, encoding_size));
    if (std::find(std::begin(kServiceEncodings), std::end(kServiceEncodings), c.encoding) ==
        std::end(kServiceEncodings)) {
      fail("unsupported encoding " + shown(c.encoding) + " (this server takes cdr or json)");
      return;
    }
    c.payload = std::string(frame.substr(kServiceCallHeader + encoding_size));
    out.call = std::move(c);
  }
}

void ClientProtocol::handle_text(std::string_view frame, Outcome& out) {
  out.clear();
  auto error = [&](const std::string& m) { out.replies.push_back(status_json(StatusLevel::Error, m)); };
  const std::optional<nlohmann::json> request = parse_request(frame, out);
  if (!request) return;
  const nlohmann::json& j = *request;
  const auto op_it = j.find("op");
  const auto& op = op_it->get_ref<const std::string&>();
  Problems problems;
  if (op == "subscribe") {
    subscribe(j, by_channel_, count_, out, problems);
  } else if (op == "unsubscribe") {
    unsubscribe(j, by_channel_, count_, out, problems);
  } else if ((op == "advertise" || op == "unadvertise") && !publish_topic_.empty()) {
    if (op == "advertise") {
      PublishOps::advertise(*this, j, problems);
    } else {
      PublishOps::unadvertise(*this, j, problems);
    }
  } else if (std::find(std::begin(kParameterOps), std::end(kParameterOps), op) != std::end(kParameterOps) &&
             parameters_) {
    parameter_op(op, j, out, problems);
  } else if (std::find(std::begin(kUnofferedOps), std::end(kUnofferedOps), op) != std::end(kUnofferedOps) ||
             std::find(std::begin(kParameterOps), std::end(kParameterOps), op) != std::end(kParameterOps)) {
    error("op " + shown(*op_it) + " is not supported by this server (capabilities: time" +
          (parameters_ ? ", parameters, parametersSubscribe" : "") +
          (service_count_ > 0 ? ", services" : "") + (publish_topic_.empty() ? "" : ", clientPublish") + ")");
    return;
  } else {
    error("unknown op " + shown(*op_it));
    return;
  }
  problems.flush(out.replies);
}

// ---------------------------------------------------------------------------------------------
// ClientQueue

namespace {
constexpr std::size_t kPoolMax = 16;  // spare buffers kept
}

ClientQueue::ClientQueue(QueueLimits limits) : limits_(limits) {
  limits_.max_messages = std::max<std::size_t>(limits_.max_messages, 1);
  ring_.resize(std::min<std::size_t>(limits_.max_messages, 64) + 8);
}

std::string ClientQueue::take_buffer() {
  if (pool_.empty()) return {};
  std::string b = std::move(pool_.back());
  pool_.pop_back();
  b.clear();
  return b;
}

void ClientQueue::recycle(std::string&& buffer) {
  if (buffer.capacity() == 0 || pool_.size() >= kPoolMax) return;
  pool_.push_back(std::move(buffer));
}

void ClientQueue::count_in(const Frame& f) {
  bytes_ += f.data.size();
  if (f.kind != Kind::PerStep) kept_bytes_ += f.data.size();
}

void ClientQueue::count_out(const Frame& f) {
  bytes_ -= f.data.size();
  if (f.kind != Kind::PerStep) kept_bytes_ -= f.data.size();
}

void ClientQueue::erase_at(std::size_t i) {
  Frame& f = slot(i);
  count_out(f);
  recycle(std::move(f.data));
  f.data = std::string();
  // Shift the older frames up by one: drops happen near the front, so this is short.
  for (std::size_t k = i; k > 0; --k) std::swap(slot(k), slot(k - 1));
  head_ = (head_ + 1) % ring_.size();
  --count_;
}

void ClientQueue::make_room(std::size_t incoming, bool droppable, bool& drop_incoming) {
  drop_incoming = false;
  auto over = [&] { return count_ + 1 > limits_.max_messages || bytes_ + incoming > limits_.max_bytes; };
  if (!over()) return;
  std::size_t first_droppable = 0;
  while (first_droppable < count_ && slot(first_droppable).kind != Kind::PerStep) ++first_droppable;
  // Control and latched frames alone over the limit: they are kept, the queue grows.
  if (first_droppable == count_ && !droppable) return;
  if (!in_burst_) {
    // The first drop of a burst tells the client, once; the warning counts against the limit.
    in_burst_ = true;
    ++warnings_;
    const std::string m = status_json(
        StatusLevel::Warning,
        "rbsim: this client is not keeping up: dropping the oldest per-step messages (queue limit " +
            std::to_string(limits_.max_messages) + " messages, " + std::to_string(limits_.max_bytes >> 20) +
            " MiB); latched topics are kept");
    Frame& f = emplace(Kind::Control);
    f.data.assign(m);
    count_in(f);
  }
  std::size_t i = first_droppable;
  while (over()) {
    while (i < count_ && slot(i).kind != Kind::PerStep) ++i;
    if (i == count_) break;
    erase_at(i);  // index i now holds the next newer frame
    ++dropped_;
  }
  if (over() && droppable) {
    drop_incoming = true;  // nothing droppable is left: the newest goes
    ++dropped_;
  }
}

ClientQueue::Frame& ClientQueue::emplace(Kind kind) {
  if (count_ == ring_.size()) {
    // Grow (only control and latched frames can outnumber the limit): unroll the ring first.
    std::vector<Frame> bigger(ring_.size() * 2);
    for (std::size_t i = 0; i < count_; ++i) bigger[i] = std::move(slot(i));
    ring_ = std::move(bigger);
    head_ = 0;
  }
  Frame& f = ring_[(head_ + count_) % ring_.size()];
  ++count_;
  f.kind = kind;
  f.binary = false;
  f.subscription = 0;
  f.data = take_buffer();
  return f;
}

void ClientQueue::push_text(std::string_view json) {
  push_control(json, false);
}

void ClientQueue::push_control(std::string_view data, bool binary) {
  bool drop = false;
  make_room(data.size(), false, drop);
  Frame& f = emplace(Kind::Control);
  f.binary = binary;
  f.data.assign(data);
  count_in(f);
}

void ClientQueue::push_message(Kind kind, SubscriptionId subscription, std::uint64_t log_time_ns,
                               std::span<const std::byte> payload) {
  const bool droppable = kind == Kind::PerStep;
  bool drop = false;
  make_room(kMessageDataHeader + payload.size(), droppable, drop);
  if (drop) return;
  Frame& f = emplace(droppable ? Kind::PerStep : Kind::Latched);
  f.binary = true;
  f.subscription = subscription;
  append_message_data(f.data, subscription, log_time_ns, payload);
  count_in(f);
}

void ClientQueue::push_time(std::uint64_t time_ns) {
  bool drop = false;
  make_room(9, true, drop);
  if (drop) return;
  Frame& f = emplace(Kind::PerStep);
  f.binary = true;
  append_time(f.data, time_ns);
  count_in(f);
}

bool ClientQueue::pop(Frame& out) {
  if (count_ == 0) return false;
  Frame& f = slot(0);
  count_out(f);
  recycle(std::move(out.data));
  out.kind = f.kind;
  out.binary = f.binary;
  out.subscription = f.subscription;
  out.data = std::move(f.data);
  f.data = std::string();
  head_ = (head_ + 1) % ring_.size();
  --count_;
  if (in_burst_ && count_ <= limits_.max_messages / 2 && bytes_ <= limits_.max_bytes / 2) in_burst_ = false;
  return true;
}

std::size_t ClientQueue::front_size() const {
  return count_ == 0 ? 0 : slot(0).data.size();
}

void ClientQueue::remove_subscription(SubscriptionId subscription) {
  std::size_t i = 0;
  while (i < count_) {
    const Frame& f = slot(i);
    if (f.kind != Kind::Control && f.binary && f.subscription == subscription && !f.data.empty() &&
        f.data[0] == '\x01') {
      erase_at(i);  // index i now holds the next newer frame
      continue;
    }
    ++i;
  }
}

}  // namespace rbsim::foxglove
