// ROS 2 services over the middleware seam (rbsim/middleware.hpp): a server takes requests into a
// bounded queue and hands them to the caller's thread in serve(), so the node handles requests at
// its step boundary without locks around the world, a flood costs at most the queue (excess
// dropped and counted), and serve()'s budget keeps the step rate. A client's requests carry its id
// and a sequence number (RequestHeader); the reply carries them back and reaches that client only.
// How a backend puts this on the wire is its own (node/dds: rmw_cyclonedds_cpp's request header
// and rq/rr topics).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "rbsim/bytes.hpp"
#include "rbsim/interfaces.hpp"
#include "rbsim/middleware.hpp"
#include "rbsim/status.hpp"

namespace rbsim::node {

// Who called and which call it is: what a reply carries back.
struct RequestHeader {
  std::uint64_t guid = 0;  // the client's id (ServiceClient::id())
  std::int64_t seq = 0;    // the client's sequence number of the call
  // The backend's own note of how to reach the caller (DDS: its request writer's instance
  // handle), set on what a server hands its handler, for a reply written later
  // (ServiceServer::reply). Not part of the call's identity.
  std::uint64_t route = 0;
  bool operator==(const RequestHeader& o) const { return guid == o.guid && seq == o.seq; }
};

struct ServiceOptions {
  // A node's endpoint: listed among the node's endpoints on the ROS 2 graph, and announcing its
  // request and reply type hashes where the backend does (rmw_cyclonedds_cpp's USER_DATA).
  bool in_graph = false;
  std::size_t queue_limit = 64;               // requests waiting for serve(); more are dropped
  std::size_t max_request_bytes = 64 * 1024;  // larger requests are dropped unread
  // How long a reply waits (retried at each serve()) for the client's reply reader to match.
  double client_match_timeout_s = 0.1;
  // Called (on the middleware's thread, must not block) after a request was queued: one thread
  // serving several servers waits for all of them at once.
  std::function<void()> on_arrival;
};

// What a server did with the requests it received (every received request is counted once in
// exactly one of the outcomes, or is still queued or pending).
struct ServiceStats {
  std::uint64_t received = 0;
  std::uint64_t answered = 0;          // a reply written
  std::uint64_t unanswered = 0;        // the handler wrote no reply (one written later by
                                       // ServiceServer::reply() is counted again, by its outcome)
  std::uint64_t dropped_full = 0;      // the queue was full
  std::uint64_t dropped_large = 0;     // over max_request_bytes
  std::uint64_t malformed = 0;         // not a service sample (bad CDR header, shorter than the header)
  std::uint64_t client_gone = 0;       // the client vanished before the reply: no reply
  std::uint64_t client_unmatched = 0;  // its reply reader never matched in time: no reply
  std::uint64_t write_failed = 0;
  // Now: requests waiting for serve(); replies waiting for a match (as the last serve() left them).
  std::size_t queued = 0, pending = 0;
};

// Answers a request: `request` is its body as a CDR message (encapsulation header included),
// `reply` (cleared, its storage reused) receives the reply's body the same way. Returns false to
// send no reply.
using ServiceHandler =
    std::function<bool(const RequestHeader& header, std::span<const std::byte> request, Bytes& reply)>;

class ServiceServerImpl;  // rbsim/middleware_backend.hpp
class ServiceClientImpl;

class ServiceServer {
 public:
  using Handler = ServiceHandler;

  // `service` is the fully qualified ROS name ("/rbsim/pause"), `srv_type` "pkg/srv/Name".
  static Result<ServiceServer> create(const Participant& participant, std::string_view service,
                                      std::string_view srv_type, const ServiceOptions& options = {});
  ServiceServer(std::unique_ptr<ServiceServerImpl> impl, std::string service);  // for backends
  ServiceServer(ServiceServer&&) noexcept;
  ServiceServer& operator=(ServiceServer&&) = delete;
  ~ServiceServer();

  // Handles up to `budget` queued requests on the caller's thread, writing their replies, and
  // retries the replies waiting for their client's reader. Returns the requests handled.
  std::size_t serve(const Handler& handler, std::size_t budget = SIZE_MAX);
  // Answers, later, a request whose handler wrote no reply (an action's get_result, answered when
  // its goal ends): `header` as the handler got it. On the thread that calls serve() only.
  void reply(const RequestHeader& header, std::span<const std::byte> reply);
  // Waits until a request is queued or `timeout_s` passes; true when one is.
  bool wait(double timeout_s);
  ServiceStats stats() const;  // from any thread
  const std::string& service() const { return service_; }
  ServiceServerImpl& impl() const { return *impl_; }  // for backends

 private:
  std::unique_ptr<ServiceServerImpl> impl_;
  std::string service_;
  TypeRegistration type_;  // a node's endpoint: its service type in the node's cache
};

// A ServiceServer::Handler from a typed function: the request decoded as `Req` (a request struct of
// rbsim/interfaces.hpp), `answer(header, request)` returns the `Res` to send. A request that does not
// decode gets `on_malformed(error)`'s reply instead, or none when that returns nullopt (a type with
// no field to say so, such as GetParameters' response).
template <class Req, class Res, class Answer, class OnMalformed>
ServiceServer::Handler typed_handler(Answer answer, OnMalformed on_malformed) {
  return [answer = std::move(answer), on_malformed = std::move(on_malformed)](
             const RequestHeader& header, std::span<const std::byte> request, Bytes& reply) {
    // The codecs of rbsim/interfaces.hpp, or of the request's own namespace (found by
    // argument-dependent lookup: rbsim/simulation_interfaces.hpp's).
    using msgs::decode;
    using msgs::encode;
    Req req;
    if (Status st = decode(request, req); !st) {
      const std::optional<Res> res = on_malformed(st.error());
      if (!res) return false;
      encode(*res, reply);
      return true;
    }
    encode(static_cast<const Res&>(answer(header, req)), reply);
    return true;
  };
}

struct ClientOptions {
  // A node's endpoint: as ServiceOptions::in_graph.
  bool in_graph = false;
};

// A service client: its id in every request header; replies with another id (other clients') are
// skipped.
class ServiceClient {
 public:
  static Result<ServiceClient> create(const Participant& participant, std::string_view service,
                                      std::string_view srv_type, const ClientOptions& options = {});
  explicit ServiceClient(std::unique_ptr<ServiceClientImpl> impl);  // for backends
  ServiceClient(ServiceClient&&) noexcept;
  ServiceClient& operator=(ServiceClient&&) = delete;
  ~ServiceClient();

  // True once a server can take requests and answer (as rmw_service_server_is_available).
  bool server_ready() const;
  [[nodiscard]] Status wait_for_server(double timeout_s);
  // Sends a request (its body as a CDR message); returns its sequence number.
  Result<std::int64_t> send(std::span<const std::byte> request);
  // Takes one reply addressed to this client into `reply` (its body as a CDR message); false when
  // there is none now.
  bool take_reply(RequestHeader& header, Bytes& reply);
  // Waits up to `timeout_s` for a reply to arrive; true when one may be there.
  bool wait_reply(double timeout_s);
  // send() and waits up to `timeout_s` for the reply to that request (others are dropped).
  Result<Bytes> call(std::span<const std::byte> request, double timeout_s);
  std::uint64_t id() const;                           // the guid of its request headers
  ServiceClientImpl& impl() const { return *impl_; }  // for backends

 private:
  std::unique_ptr<ServiceClientImpl> impl_;
  TypeRegistration type_;  // a node's endpoint: its service type in the node's cache
};

}  // namespace rbsim::node
