// Servers of one node served together on one thread (the node's parameter and control services,
// the player's): each created as the node's endpoint (ServiceOptions::in_graph: on the graph, with
// its type hashes where the middleware announces them); the thread wakes on any server's
// arrival, or every 20 ms to retry replies waiting for their client's reader, so whatever the
// caller's loop is doing (a paused run, a paused replay) requests are answered.
//
// Service introspection (REP 2012), as rcl does it for a service: off by default; once configured
// on, each server publishes on "<service>/_service_event" (type "pkg/srv/Name_Event",
// rbsim/service_event.hpp) a REQUEST_RECEIVED event when it takes a request and a RESPONSE_SENT
// event when its handler has made the reply (the backend writes it right after), with the
// request's client id and sequence number, stamped with the system clock (the node's ROS time:
// rbsim's use_sim_time is always false). Metadata leaves the request and response sequences
// empty; contents carries them, re-aligned into the event by msgs's schema walk.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "rbsim/service.hpp"
#include "rbsim/service_event.hpp"

namespace rbsim::node {

// Off, Metadata, Contents ("disabled", "metadata", "contents": to_string, parse_introspection_state).
using msgs::IntrospectionState;
using msgs::parse_introspection_state;
// The event publishers' QoS: rcl's default publisher options (rmw_qos_profile_default: reliable,
// volatile, keep last 10), which rcl_service_configure_service_introspection is given by rclcpp's
// demos (SystemDefaultsQoS, the same on every shipped middleware).
QosSpec service_event_qos();
// rcl's client_gid of a request from rbsim's RequestHeader: rmw_cyclonedds_cpp copies the 8-byte
// guid of its request header into the first half of the 16-byte writer_guid (the second half is
// its local instance handle of the client's writer, meaningless outside the server's process:
// zero here), so the guid's bytes as they travel (little endian) come first.
std::array<std::uint8_t, 16> client_gid(const RequestHeader& header);

class ServiceSet {
 public:
  ServiceSet() = default;
  ~ServiceSet();  // stop()
  ServiceSet(const ServiceSet&) = delete;
  ServiceSet& operator=(const ServiceSet&) = delete;

  // Adds the server <node>/<name> of `srv_type` ("pkg/srv/Name"), served by `handler` once
  // start() was called; larger requests than `max_request_bytes` are dropped unread
  // (ServiceOptions'). Not after start().
  [[nodiscard]] Status add(const Participant& participant, const std::string& node, std::string_view name,
                           std::string_view srv_type, ServiceServer::Handler handler,
                           std::size_t max_request_bytes = ServiceOptions{}.max_request_bytes);
  // Starts the serving thread (handlers run there, `budget` requests per server in turn).
  void start(std::size_t budget = 8);
  // Stops serving (a request being handled is answered first); idempotent.
  void stop();
  // Every server's counters, in the order added (from any thread).
  std::vector<ServiceStats> stats() const;

  // Service introspection for every server added so far, from any thread, before or after
  // start(): Off destroys the event publishers (as rcl does: nothing on the graph, nothing
  // published, one relaxed load per request); Metadata or Contents creates them (once) and
  // publishes from the next request on. Fails, the state unchanged, when a publisher cannot be
  // created.
  [[nodiscard]] Status configure_introspection(const Participant& participant, IntrospectionState state);
  IntrospectionState introspection() const { return state_.load(std::memory_order_relaxed); }
  // Events published, and events not published (the publish failed).
  std::uint64_t events_published() const { return events_published_.load(); }
  std::uint64_t events_failed() const { return events_failed_.load(); }

 private:
  void serve_loop(std::size_t budget);
  // The serving thread: one event of server `k` (the request or the response given, the other empty).
  void introspect(std::size_t k, msgs::ServiceEventType type, const RequestHeader& header,
                  std::span<const std::byte> request, std::span<const std::byte> response);
  std::mutex mutex_;  // guards arrived_ and stopping_
  std::condition_variable wake_;
  bool arrived_ = false, stopping_ = false;
  std::thread thread_;
  std::vector<ServiceServer::Handler> handlers_;

  // Introspection: per server its codec and, while on, its event publisher.
  struct Events {
    std::string topic;  // <service>/_service_event
    msgs::ServiceEventCodec codec;
    std::optional<Publisher> publisher;
  };
  std::atomic<IntrospectionState> state_{IntrospectionState::Off};
  std::mutex events_mutex_;  // guards events_' publishers and event_cdr_ (configure vs. the serving thread)
  std::vector<Events> events_;
  Bytes event_cdr_;
  std::atomic<std::uint64_t> events_published_{0}, events_failed_{0};

  std::vector<ServiceServer> servers_;  // last: gone (their listeners with them) before the mutex
};

}  // namespace rbsim::node
