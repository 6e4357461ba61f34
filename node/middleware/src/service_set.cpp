// Servers of one node on one serving thread, and their introspection events (service_set.hpp).
#include "rbsim/service_set.hpp"
#include "rbsim/time.hpp"

#include <chrono>
#include <cstring>

namespace rbsim::node {

QosSpec service_event_qos() {
  QosSpec q;
  q.transient_local = false;
  q.keep_all = false;
  q.depth = 10;
  return q;
}

std::array<std::uint8_t, 16> client_gid(const RequestHeader& header) {
  std::array<std::uint8_t, 16> gid{};
  std::memcpy(gid.data(), &header.guid, sizeof header.guid);  // little endian, as on the wire
  return gid;
}

ServiceSet::~ServiceSet() {
  stop();
}

Status ServiceSet::add(const Participant& participant, const std::string& node, std::string_view name,
                       std::string_view srv_type, ServiceServer::Handler handler,
                       std::size_t max_request_bytes) {
  ServiceOptions so;
  so.in_graph = true;
  so.max_request_bytes = max_request_bytes;
  so.on_arrival = [this] {
    {
      const std::lock_guard lock(mutex_);
      arrived_ = true;
    }
    wake_.notify_one();
  };
  // Made now, so turning introspection on later cannot fail on a type: every service the node
  // serves has a shipped definition.
  Result<msgs::ServiceEventCodec> codec = msgs::ServiceEventCodec::create(srv_type);
  if (!codec) return codec.error();
  Result<ServiceServer> s = ServiceServer::create(participant, node + "/" + std::string(name), srv_type, so);
  if (!s) return s.error();
  const std::size_t k = servers_.size();
  {
    const std::lock_guard lock(events_mutex_);
    events_.push_back(
        {s.value().service() + std::string(msgs::kServiceEventTopicSuffix), std::move(codec.value()), {}});
  }
  servers_.push_back(std::move(s.value()));
  // The handler, with the two events around it (nothing but a relaxed load while off).
  handlers_.push_back([this, k, handler = std::move(handler)](
                          const RequestHeader& header, std::span<const std::byte> request, Bytes& reply) {
    const bool on = state_.load(std::memory_order_relaxed) != IntrospectionState::Off;
    if (on) introspect(k, msgs::ServiceEventType::RequestReceived, header, request, {});
    const bool answered = handler(header, request, reply);
    if (on && answered) introspect(k, msgs::ServiceEventType::ResponseSent, header, {}, reply);
    return answered;
  });
  return Ok{};
}

Status ServiceSet::configure_introspection(const Participant& participant, IntrospectionState state) {
  const std::lock_guard lock(events_mutex_);
  if (state == IntrospectionState::Off) {
    state_.store(state, std::memory_order_relaxed);
    for (Events& e : events_) e.publisher.reset();
    return Ok{};
  }
  const bool was_off = state_.load(std::memory_order_relaxed) == IntrospectionState::Off;
  for (Events& e : events_) {
    if (e.publisher) continue;
    Result<Publisher> p =
        Publisher::create(participant, RawTopic{e.topic, e.codec.event_type()}, service_event_qos());
    if (!p) {
      if (was_off) {
        for (Events& undo : events_) undo.publisher.reset();  // off, as it was
      }
      return with_context(e.topic + ": ", p.error());
    }
    e.publisher.emplace(std::move(p.value()));
  }
  state_.store(state, std::memory_order_relaxed);
  return Ok{};
}

void ServiceSet::introspect(std::size_t k, msgs::ServiceEventType type, const RequestHeader& header,
                            std::span<const std::byte> request, std::span<const std::byte> response) {
  const std::lock_guard lock(events_mutex_);
  const IntrospectionState state = state_.load(std::memory_order_relaxed);
  Events& e = events_[k];
  if (state == IntrospectionState::Off || !e.publisher) return;  // turned off meanwhile
  msgs::ServiceEventInfo info;
  info.event_type = type;
  info.stamp = msgs::time_from_ns(static_cast<std::uint64_t>(wall_ns()));
  info.client_gid = client_gid(header);
  info.sequence_number = header.seq;
  const bool contents = state == IntrospectionState::Contents;
  Status st = e.codec.encode(info, contents ? request : std::span<const std::byte>{},
                             contents ? response : std::span<const std::byte>{}, event_cdr_);
  // A request that does not read as its type (its handler answers it as malformed) still has its
  // event, without the contents that cannot be re-aligned.
  if (!st) st = e.codec.encode(info, {}, {}, event_cdr_);
  if (st && e.publisher->publish(event_cdr_)) {
    ++events_published_;
  } else {
    ++events_failed_;
  }
}

void ServiceSet::start(std::size_t budget) {
  if (!thread_.joinable()) thread_ = std::thread([this, budget] { serve_loop(budget); });
}

void ServiceSet::stop() {
  {
    const std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_one();
  if (thread_.joinable()) thread_.join();
}

std::vector<ServiceStats> ServiceSet::stats() const {
  std::vector<ServiceStats> out;
  for (const ServiceServer& s : servers_) out.push_back(s.stats());
  return out;
}

void ServiceSet::serve_loop(std::size_t budget) {
  while (true) {
    {
      std::unique_lock lock(mutex_);
      // Bounded wait: replies waiting for their client's reader are retried at each serve().
      wake_.wait_for(lock, std::chrono::milliseconds(20), [this] { return arrived_ || stopping_; });
      if (stopping_) return;
      arrived_ = false;
    }
    for (std::size_t k = 0; k < servers_.size(); ++k) servers_[k].serve(handlers_[k], budget);
  }
}

}  // namespace rbsim::node
