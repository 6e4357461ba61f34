// ROS 2 services over Cyclone DDS on rmw_cyclonedds_cpp's wire format, so ROS 2 clients and servers
// using it talk to rbsim's:
//   - service "/rbsim/pause" is two topics, requests on "rq/rbsim/pauseRequest" and replies on
//     "rr/rbsim/pauseReply", of types "pkg::srv::dds_::Name_Request_" / "Name_Response_";
//   - every request and reply is CDR with rmw_cyclonedds's request header (cdds_request_header_t:
//     u64 client id, i64 sequence number) first, then the message's fields, aligned as if the header
//     were not there (it is 16 bytes, a multiple of every alignment); a reply carries its request's
//     header back unchanged, and a client keeps the replies whose id is its own;
//   - the QoS is rmw_qos_profile_services_default (reliable, volatile, keep last 10), and each
//     endpoint's USER_DATA says "clientid=<id>;" or "serviceid=<id>;" (one id for an endpoint pair)
//     so a server can tell whether a client's reply reader is matched before it answers.
//
// The server takes requests on Cyclone's receive thread (a DDS listener) into a bounded queue and
// hands them to the caller's thread in serve(): the node handles requests at its step boundary
// without locks around the world, a flood costs at most the queue (excess dropped and counted),
// and serve()'s budget keeps the step rate. A reply to a client whose reply reader is not matched
// yet is kept (bounded) and retried at later serve() calls for a short while, instead of waiting as
// rmw_cyclonedds does (up to 100 ms inside rmw_send_response); a client that is gone gets none.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "rbsim/bytes.hpp"
#include "rbsim/dds.hpp"
#include "rbsim/interfaces.hpp"
#include "rbsim/status.hpp"

namespace rbsim::node {

// rmw_cyclonedds_cpp's cdds_request_header_t, before the body of every request and reply.
struct RequestHeader {
  // The client's id: rmw_cyclonedds puts its request writer's DDS instance handle here, and its
  // client keeps only replies carrying it.
  std::uint64_t guid = 0;
  std::int64_t seq = 0;  // the client's sequence number of the call
  bool operator==(const RequestHeader&) const = default;
};
inline constexpr std::size_t kRequestHeaderBytes = 16;

// "/rbsim/pause" -> "rq/rbsim/pauseRequest" and "rr/rbsim/pauseReply".
std::string service_request_topic(std::string_view service);
std::string service_reply_topic(std::string_view service);
// "std_srvs/srv/Trigger" -> "std_srvs::srv::dds_::Trigger_Request_" and "..._Response_".
std::string service_request_type(std::string_view srv_type);
std::string service_response_type(std::string_view srv_type);

// A service sample: `header` then the fields of `body` (a CDR message with its encapsulation
// header, as msgs' encoders write it) into `out` (replaced).
void wrap_service_sample(const RequestHeader& header, std::span<const std::byte> body, Bytes& out);
// The header of a service sample, and its fields as a CDR message of their own (encapsulation
// header included) in `body` (replaced). Fails when the sample is not plain little-endian CDR or is
// too short to hold the header.
Result<RequestHeader> unwrap_service_sample(std::span<const std::byte> sample, Bytes& body);

// How another participant knows one of our endpoints: its DDS GUID (prefix and entity id, the
// Jazzy GID; Humble pads it to 24 bytes) and, inside this process, its instance handle.
struct EndpointId {
  std::array<std::uint8_t, 16> guid{};
  std::uint64_t instance_handle = 0;
};

struct ServiceOptions {
  // Appended to each endpoint's USER_DATA after "serviceid=<id>;" (later "typehash=RIHS01_...;").
  std::string request_user_data, reply_user_data;
  std::size_t queue_limit = 64;               // requests waiting for serve(); more are dropped
  std::size_t max_request_bytes = 64 * 1024;  // larger requests are dropped unread
  // How long a reply waits (retried at each serve()) for the client's reply reader to match.
  double client_match_timeout_s = 0.1;
  // Called (on Cyclone's receive thread, must not block) after a request was queued: one thread
  // serving several servers waits for all of them at once.
  std::function<void()> on_arrival;
};

// What a server did with the requests it received (every received request is counted once in
// exactly one of the outcomes, or is still queued or pending).
struct ServiceStats {
  std::uint64_t received = 0;
  std::uint64_t answered = 0;          // a reply written
  std::uint64_t unanswered = 0;        // the handler chose not to reply
  std::uint64_t dropped_full = 0;      // the queue was full
  std::uint64_t dropped_large = 0;     // over max_request_bytes
  std::uint64_t malformed = 0;         // not a service sample (bad CDR header, shorter than the header)
  std::uint64_t client_gone = 0;       // its request writer vanished before the reply: no reply
  std::uint64_t client_unmatched = 0;  // its reply reader never matched in time: no reply
  std::uint64_t write_failed = 0;
  // Now: requests waiting for serve(); replies waiting for a match (as the last serve() left them).
  std::size_t queued = 0, pending = 0;
};

class ServiceServer {
 public:
  // Answers a request: `request` is its body as a CDR message (encapsulation header included),
  // `reply` (cleared, its storage reused) receives the reply's body the same way. Returns false to
  // send no reply.
  using Handler =
      std::function<bool(const RequestHeader& header, std::span<const std::byte> request, Bytes& reply)>;

  // `service` is the fully qualified ROS name ("/rbsim/pause"), `srv_type` "pkg/srv/Name".
  static Result<ServiceServer> create(const Participant& participant, std::string_view service,
                                      std::string_view srv_type, const ServiceOptions& options = {});
  ServiceServer(ServiceServer&&) noexcept;
  ServiceServer& operator=(ServiceServer&&) = delete;
  ~ServiceServer();

  // Handles up to `budget` queued requests on the caller's thread, writing their replies, and
  // retries the replies waiting for their client's reader. Returns the requests handled.
  std::size_t serve(const Handler& handler, std::size_t budget = SIZE_MAX);
  // Waits until a request is queued or `timeout_s` passes; true when one is.
  bool wait(double timeout_s);
  ServiceStats stats() const;  // from any thread
  EndpointId request_reader() const;
  EndpointId reply_writer() const;
  const std::string& service() const;

 private:
  struct Impl;
  explicit ServiceServer(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// A ServiceServer::Handler from a typed function: the request decoded as `Req` (a request struct of
// rbsim/interfaces.hpp), `answer(header, request)` returns the `Res` to send. A request that does not
// decode gets `on_malformed(error)`'s reply instead, or none when that returns nullopt (a type with
// no field to say so, such as GetParameters' response).
template <class Req, class Res, class Answer, class OnMalformed>
ServiceServer::Handler typed_handler(Answer answer, OnMalformed on_malformed) {
  return [answer = std::move(answer), on_malformed = std::move(on_malformed)](
             const RequestHeader& header, std::span<const std::byte> request, Bytes& reply) {
    Req req;
    if (Status st = msgs::decode(request, req); !st) {
      const std::optional<Res> res = on_malformed(st.error());
      if (!res) return false;
      msgs::encode(*res, reply);
      return true;
    }
    msgs::encode(static_cast<const Res&>(answer(header, req)), reply);
    return true;
  };
}

struct ClientOptions {
  // Appended to each endpoint's USER_DATA after "clientid=<id>;".
  std::string request_user_data, reply_user_data;
};

// A service client as rmw_cyclonedds's: its id in every request header is its request writer's
// instance handle; replies with another id (other clients') are skipped.
class ServiceClient {
 public:
  static Result<ServiceClient> create(const Participant& participant, std::string_view service,
                                      std::string_view srv_type, const ClientOptions& options = {});
  ServiceClient(ServiceClient&&) noexcept;
  ServiceClient& operator=(ServiceClient&&) = delete;
  ~ServiceClient();

  // True once both topics have a matched server endpoint (as rmw_service_server_is_available).
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
  std::uint64_t id() const;  // the guid of its request headers
  EndpointId request_writer() const;
  EndpointId reply_reader() const;

 private:
  struct Impl;
  explicit ServiceClient(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace rbsim::node
