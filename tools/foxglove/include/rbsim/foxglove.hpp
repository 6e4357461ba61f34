// The Foxglove WebSocket server: rbsim's topics served live to Foxglove (app.foxglove.dev or the
// desktop app) with no ROS install, the protocol foxglove_bridge speaks
// (https://github.com/foxglove/ws-protocol, docs/spec.md).
//
// Three layers, the first two pure (no I/O, no threads) so that tests and the fuzzer drive them
// directly:
//  - the protocol: the JSON a server sends (serverInfo, advertise, status, advertiseServices,
//    parameterValues, serviceCallFailure), the binary frames (messageData, time,
//    serviceCallResponse), the subprotocol choice, and ClientProtocol, which parses one client
//    frame, keeps that client's subscriptions and hands over its parameter requests and service
//    calls as data;
//  - flow control: ClientQueue, the bounded per-client queue that drops the oldest per-step
//    message (never a latched one or a control message) when a client falls behind;
//  - the Server (websocketpp on its own I/O thread) and FoxgloveSink, the Sink that publishes a
//    run into it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "rbsim/control.hpp"
#include "rbsim/core.hpp"
#include "rbsim/interfaces.hpp"
#include "rbsim/msgs.hpp"
#include "rbsim/sink.hpp"

namespace rbsim::foxglove {

namespace detail {
struct PublishOps;
}

// ---------------------------------------------------------------------------------------------
// Protocol

// The subprotocols served, in the server's order of preference; a client offering neither is
// refused in the handshake.
inline constexpr std::string_view kSubprotocols[] = {"foxglove.sdk.v1", "foxglove.websocket.v1"};
// The subprotocol to answer a client that offered `offered` (in its order): the first one it
// offers that we speak (the client's choice); nullopt refuses the connection.
std::optional<std::string_view> choose_subprotocol(std::span<const std::string> offered);

// Client frames larger than this are refused (a status error from ClientProtocol; the transport
// closes a connection that sends one, as it would otherwise have to buffer it).
inline constexpr std::size_t kMaxClientFrame = 1 << 20;
// Client frames up to this size are read whole and refused with a status error when over
// kMaxClientFrame; only a larger one makes the transport close the connection (1009) mid-frame.
// Reading the frame before answering is what lets the answer arrive: closing a socket with unread
// data resets the connection, and the peer's kernel then drops the close frame it had not read.
inline constexpr std::size_t kMaxReadFrame = 16 * kMaxClientFrame;

enum class StatusLevel : std::uint8_t { Info = 0, Warning = 1, Error = 2 };

// A channel the server advertises (ids are 1-based positions in the server's channel list).
struct ChannelSpec {
  std::string topic;             // "/rbsim/body_states"
  std::string encoding = "cdr";  // message encoding
  std::string schema_name;       // "rbsim_msgs/msg/BodyStates"
  std::string schema;            // the ros2msg text, as in MCAP
  std::string schema_encoding = "ros2msg";
  bool latched = false;  // the last message goes to every new subscription at once
};
using ChannelId = std::uint32_t;
using SubscriptionId = std::uint32_t;
using ServiceId = std::uint32_t;
using CallId = std::uint32_t;

// With a controller (rbsim node) the server also offers the capabilities parameters,
// parametersSubscribe, services and clientPublish; a service call's request comes in one of these encodings,
// the client's choice per call (the spec's "one of the encodings supported by the server"), and
// its response in the same one. cdr is first: Foxglove Studio calls in the first one it knows.
inline constexpr std::string_view kServiceEncodings[] = {"cdr", "json"};

// `control`: the capabilities above and supportedEncodings; else `time`, and with `services` alone
// (rbsim replay's player) the services capability, in the same encodings (hosted services convert
// json by their schemas).
std::string server_info_json(std::string_view name, std::string_view session_id, bool control = false,
                             bool services = false);
// Every channel of `channels`, channel i (0-based) with id i + 1.
std::string advertise_json(std::span<const ChannelSpec> channels);
std::string status_json(StatusLevel level, std::string_view message);
// One status error naming a request's problems ("OP: a; b", the first five, then how many more);
// "" when there are none.
std::string problems_status_json(std::string_view op, const std::vector<std::string>& problems);

// A service the server offers (ids are 1-based positions in the server's service list).
struct ServiceSpec {
  std::string name;             // "/rbsim/pause"
  std::string type;             // "std_srvs/srv/Trigger"
  std::string request_schema;   // ros2msg text of <type>_Request
  std::string response_schema;  // ros2msg text of <type>_Response
};
// The spec of service <node>/<name> of ROS 2 type `type`: the request and response schemas are
// msgs::ros2msg_schema of <type>_Request and _Response (each half of the .srv text, then the types
// it uses, as rosbag2 writes them).
ServiceSpec service_spec(std::string_view node, std::string_view name, std::string_view type);
// A service the server offers beside the steering's (rbsim replay's player services, rbsim node's
// simulation_interfaces services, rbsim bridge's forwards of them to the node): its spec,
// and its handler, given a request's CDR payload, returning the response's (an error: the call
// fails with its message). Handlers run on the server's one service thread, one call at a time,
// so one may block for a while (a seek waits for the player). A handler sees CDR only: a call in
// json is converted to it and its reply back by the spec's schemas (msgs::MessageDecoder's from_json
// and to_json; src/hosted.hpp).
struct HostedService {
  ServiceSpec spec;
  std::function<Result<std::string>(std::string_view request)> call;
};
// Each service with `request` and `response` (encoding cdr, schemaEncoding ros2msg) and, for
// clients of the older form (Foxglove Studio 1.x), `requestSchema` and `responseSchema`.
std::string advertise_services_json(std::span<const ServiceSpec> services);
// parameterValues (with `id` when given): a double is sent with "type": "float64", a double array
// with "float64_array", a byte array base64-encoded with "byte_array", other values as JSON.
std::string parameter_values_json(std::span<const msgs::Parameter> parameters,
                                  const std::optional<std::string>& id = std::nullopt);
std::string service_call_failure_json(ServiceId service, CallId call, std::string_view message);

// The binary frames a server sends (little endian): messageData is opcode 0x01, the subscription
// id (uint32), the log time (uint64 ns) and the payload; time is opcode 0x02 and the time (ns).
inline constexpr std::size_t kMessageDataHeader = 1 + 4 + 8;
void append_message_data(std::string& out, SubscriptionId subscription, std::uint64_t log_time_ns,
                         std::span<const std::byte> payload);
void append_time(std::string& out, std::uint64_t time_ns);
// serviceCallResponse: opcode 0x03, service id, call id, encoding length (uint32), encoding, payload.
void append_service_call_response(std::string& out, ServiceId service, CallId call, std::string_view encoding,
                                  std::span<const std::byte> payload);
// A client's service call request (opcode 0x02) is at least this long: opcode, service id, call
// id, encoding length.
inline constexpr std::size_t kServiceCallHeader = 1 + 4 + 4 + 4;

// A client's parameter request, parsed (names are not checked: the controller knows them).
struct ParameterRequest {
  enum class Op : std::uint8_t { Get, Set, Subscribe, Unsubscribe };
  Op op = Op::Get;
  std::vector<std::string> names;  // Get, Subscribe, Unsubscribe; empty: every parameter
  // Set: the values as typed from JSON: true/false bool, 2 integer, 2.5 double (or any number
  // with "type": "float64"), "x" string, base64 with "type": "byte_array" bytes, arrays of one
  // of these. A JSON integer without a type hint may stand for a double (JSON cannot tell 2.0 from
  // 2): `untyped_integer[k]` says so, and the server types it by the parameter's declared type.
  std::vector<msgs::Parameter> values;
  std::vector<bool> untyped_integer;
  std::optional<std::string> id;  // Get, Set: echoed in the parameterValues answer
};
// clientPublish (rbsim node only): a client may advertise channels on one topic, <node>/command_in,
// schema rbsim_msgs/msg/Command, in one of these encodings (cdr: the CDR of Command.msg; json: its
// fields by name), at most kMaxClientChannels at a time; each message it sends on one is a command
// (src/command_in.cpp decodes it) applied at the next step boundary.
inline constexpr std::string_view kCommandInSuffix = "command_in";
inline constexpr std::string_view kCommandInSchema = msgs::CommandMessage::kType;
inline constexpr std::string_view kClientPublishEncodings[] = {"cdr", "json"};
inline constexpr std::size_t kMaxClientChannels = 16;
// A client's messageData (opcode 0x01): opcode, channel id (uint32), payload.
inline constexpr std::size_t kClientMessageHeader = 1 + 4;
struct ClientMessage {
  ChannelId channel = 0;  // the client's id
  std::string encoding;   // its channel's
  std::string payload;
};

// A client's service call, its header checked (a known service, an offered encoding, within
// kMaxClientFrame); the payload is the service's to decode.
struct ServiceCall {
  ServiceId service = 0;
  CallId call = 0;
  std::string encoding;
  std::string payload;
};

// One client's side of the protocol: parses its frames and keeps its subscriptions. Channels are
// 1 .. channel_count; with `parameters` the parameter ops are accepted, and services are
// 1 .. service_count. Any input is answered, never thrown on: a malformed frame, an unknown op, an
// op not offered, an unknown channel or subscription id, a binary frame other than a service call
// or (with accept_publish) a message on an advertised client channel, or a frame over
// kMaxClientFrame gives one status error per frame (naming at most a few of the problems), and the
// valid parts of a subscribe, unsubscribe, advertise, unadvertise or setParameters still take
// effect. A service call with a readable header but an unknown service,
// an encoding not offered or a payload over the limit gets a serviceCallFailure instead.
class ClientProtocol {
 public:
  explicit ClientProtocol(std::uint32_t channel_count, bool parameters = false,
                          std::uint32_t service_count = 0);

  struct Subscription {
    SubscriptionId id = 0;
    ChannelId channel = 0;
    bool operator==(const Subscription&) const = default;
  };
  struct Outcome {
    std::vector<Subscription> subscribed;        // new, in request order
    std::vector<Subscription> unsubscribed;      // ended, in request order
    std::vector<std::string> replies;            // JSON text frames to send back (status, serviceCallFailure)
    std::optional<ParameterRequest> parameters;  // a parameter op to carry out
    std::optional<ServiceCall> call;             // a service call to carry out
    std::optional<ClientMessage> published;      // a message on one of the client's channels
    void clear() {
      subscribed.clear();
      unsubscribed.clear();
      replies.clear();
      parameters.reset();
      call.reset();
      published.reset();
    }
  };
  // Handles one text frame (`out` is cleared first).
  void handle_text(std::string_view frame, Outcome& out);
  // Handles one binary frame (`out` is cleared first).
  void handle_binary(std::string_view frame, Outcome& out);

  // The subscription on `channel`, if any.
  std::optional<SubscriptionId> subscription(ChannelId channel) const;
  // Offers clientPublish: channels advertised on `topic` with kCommandInSchema and an encoding of
  // kClientPublishEncodings are accepted (every other advertisement is refused).
  void accept_publish(std::string topic) { publish_topic_ = std::move(topic); }
  std::size_t client_channel_count() const { return client_channels_.size(); }
  std::size_t subscription_count() const { return count_; }
  std::uint32_t channel_count() const { return static_cast<std::uint32_t>(by_channel_.size()); }

 private:
  std::vector<std::optional<SubscriptionId>> by_channel_;  // index channel - 1
  std::size_t count_ = 0;
  bool parameters_ = false;
  std::uint32_t service_count_ = 0;
  // clientPublish (src/client_publish.cpp): the accepted topic ("" when not offered) and the
  // client's channels.
  friend struct detail::PublishOps;
  std::string publish_topic_;
  struct ClientChannel {
    ChannelId id = 0;
    std::string encoding;
  };
  std::vector<ClientChannel> client_channels_;
};

// ---------------------------------------------------------------------------------------------
// Flow control

struct QueueLimits {
  std::size_t max_messages = 1024;    // frames queued for one client
  std::size_t max_bytes = 64u << 20;  // their bytes
};

// The frames waiting for one client. Control frames (serverInfo, advertise, status) and latched
// messages are never dropped; when a per-step message (or time) would go over a limit, the oldest
// queued per-step frames are dropped until it fits (the new one itself when nothing droppable is
// queued). The first drop of a burst queues one status warning; the burst ends once the queue has
// drained to half its limits. Buffers are recycled: a queue that is fed and drained at a steady
// pace does not allocate.
class ClientQueue {
 public:
  enum class Kind : std::uint8_t { Control, Latched, PerStep };
  struct Frame {
    Kind kind = Kind::Control;
    bool binary = false;
    SubscriptionId subscription = 0;  // messageData only
    std::string data;                 // the whole WebSocket message
  };

  explicit ClientQueue(QueueLimits limits = {});

  void push_text(std::string_view json);
  // A control frame: JSON text, or a binary serviceCallResponse.
  void push_control(std::string_view data, bool binary);
  void push_message(Kind kind, SubscriptionId subscription, std::uint64_t log_time_ns,
                    std::span<const std::byte> payload);
  void push_time(std::uint64_t time_ns);  // per step: droppable
  // Moves the oldest frame into `out` (whose old buffer is kept for reuse); false when empty.
  bool pop(Frame& out);
  // The size of the oldest frame (0 when empty).
  std::size_t front_size() const;
  // Removes the queued messages of an ended subscription.
  void remove_subscription(SubscriptionId subscription);

  bool empty() const { return count_ == 0; }
  std::size_t size() const { return count_; }
  std::size_t bytes() const { return bytes_; }
  // The bytes of the frames never dropped (control and latched): what a client that sends
  // requests and reads no replies piles up (the server refuses its requests past a bound).
  std::size_t kept_bytes() const { return kept_bytes_; }
  std::uint64_t dropped() const { return dropped_; }    // per-step frames dropped so far
  std::uint64_t warnings() const { return warnings_; }  // overflow bursts (one warning each)

 private:
  Frame& slot(std::size_t i) { return ring_[(head_ + i) % ring_.size()]; }
  const Frame& slot(std::size_t i) const { return ring_[(head_ + i) % ring_.size()]; }
  Frame& emplace(Kind kind);  // a new last frame with an empty recycled buffer
  void make_room(std::size_t incoming_bytes, bool droppable, bool& drop_incoming);
  void erase_at(std::size_t i);
  void recycle(std::string&& buffer);
  std::string take_buffer();

  QueueLimits limits_;
  std::vector<Frame> ring_;
  void count_in(const Frame& f);   // adds f's bytes to the totals
  void count_out(const Frame& f);  // takes them away
  std::size_t head_ = 0, count_ = 0, bytes_ = 0, kept_bytes_ = 0;
  std::vector<std::string> pool_;  // spare buffers
  std::uint64_t dropped_ = 0, warnings_ = 0;
  bool in_burst_ = false;
};

// ---------------------------------------------------------------------------------------------
// The server

struct ServerOptions {
  std::string address = "127.0.0.1";  // an IPv4 or IPv6 address; 0.0.0.0 serves every interface
  std::uint16_t port = 8765;          // 0: any free port (Server::port() says which)
  std::string name = "rbsim";         // serverInfo name
  QueueLimits queue;
  // What is handed to the socket layer per client at most (the rest waits in its queue, where
  // the drop rule applies); one frame always goes when nothing is in flight.
  std::size_t max_in_flight_bytes = 4u << 20;
  // A client that reads nothing of what is in flight for this long is disconnected.
  double stall_timeout_s = 5.0;
  // Steering: with a steering (rbsim node's Controller, rbsim bridge's relay to a node) the server
  // offers parameters, parametersSubscribe and services (control::control_services() named
  // <node>/<name>); every request goes through the steering, answered from its callbacks (never
  // waited for on the I/O thread); start() adds the observer of parameter updates
  // (Steering::on_command), so it comes before the run loop, and start() and new_session() read
  // its parameter names. The steering must outlive the server. Without one (replay) only `time` is
  // offered.
  control::Steering* steering = nullptr;
  std::string node = "/rbsim";
  // More services, after the steering's (or alone: the services capability without parameters).
  // What their handlers use must outlive the server.
  std::vector<HostedService> hosted_services;
  // Per client: parameter sets and service calls submitted and not yet answered (more are refused:
  // a serviceCallFailure or a status error), and the unread replies and other frames never dropped
  // beyond which its requests are refused unanswered (one status error per backlog).
  std::uint32_t max_pending_commands = 32;
  std::size_t max_reply_backlog_bytes = 4u << 20;

  // Access, decided before the WebSocket upgrade (the HTTP status and a one-line body):
  //  - with a token (non-empty), a client must present it, as ?token=... in the URL (percent-
  //    decoded) or an `Authorization: Bearer ...` header, else 401; compared in constant time;
  //  - a remote address with auth_failures_max failures within auth_failure_window_s gets 429
  //    (without its token being looked at) until the oldest of them is that old (0: no limit);
  //  - beyond max_clients connections (admitted and not closed), 503;
  //  - a connection that has not completed its handshake handshake_timeout_s after it was accepted
  //    is closed.
  std::string token;
  std::uint32_t auth_failures_max = 5;
  double auth_failure_window_s = 10.0;
  std::uint32_t max_clients = 16;
  double handshake_timeout_s = 5.0;
  // Without a token, start() refuses an address other hosts reach (not 127.0.0.0/8 or ::1)
  // unless this is set (rbsim's --foxglove-insecure).
  bool allow_insecure = false;
  // wss:// when set (TLS 1.2 or later, OpenSSL): the PEM certificate chain and its private key,
  // read at start() (a file that cannot be read, a key not the certificate's, or a key other
  // users may read is an error).
  std::string tls_cert, tls_key;
};

// Tokens: at least kMinTokenLength characters, printable ASCII without spaces (33..126).
inline constexpr std::size_t kMinTokenLength = 16;
// "" when `token` is one, else the rule it breaks.
std::string token_problem(std::string_view token);
// The token in `path`: the file's text without its trailing newline (\n or \r\n). Refused: a
// file group or others may read or write (chmod 600 it), one that cannot be read, and a token
// token_problem() refuses; the error names the file and the rule.
Result<std::string> read_token_file(const std::string& path);
// True for 127.0.0.0/8 and ::1 (and ::ffff:127.x.y.z): addresses only this host reaches.
bool is_loopback(std::string_view address);
// `url` with ?token=... appended (the token percent-encoded).
std::string url_with_token(std::string_view url, std::string_view token);

// "127.0.0.1:8765", "8765" (the default address), "0.0.0.0:0", "[::1]:8765" -> options.address
// and options.port; the error says what is wrong.
[[nodiscard]] Status parse_listen_address(std::string_view text, ServerOptions& options);
// "ws://127.0.0.1:8765" ("ws://[::1]:8765" for IPv6; wss:// with `tls`).
std::string websocket_url(std::string_view address, std::uint16_t port, bool tls = false);
// The link that opens Foxglove on `url`: https://app.foxglove.dev/?ds=foxglove-websocket&ds.url=...
std::string foxglove_app_link(std::string_view url);

// Counts over the server's life.
struct ServerStats {
  std::uint64_t clients = 0;             // connections accepted
  std::uint64_t refused = 0;             // handshakes refused for their subprotocols
  std::uint64_t dropped = 0;             // per-step frames dropped for slow clients
  std::uint64_t warnings = 0;            // overflow bursts warned about
  std::uint64_t disconnected = 0;        // clients disconnected for not reading
  std::uint64_t published = 0;           // messages handed to the server (publish calls that queued)
  std::uint64_t requests = 0;            // parameter requests and service calls carried out
  std::uint64_t refused_requests = 0;    // refused for a client's backlog or commands in flight
  std::uint64_t unauthorized = 0;        // handshakes refused for a missing or wrong token (401)
  std::uint64_t rate_limited = 0;        // handshakes refused for their address's failures (429)
  std::uint64_t full = 0;                // handshakes refused beyond max_clients (503)
  std::uint64_t handshake_timeouts = 0;  // connections closed for not completing the handshake
};

// Serves a fixed set of channels on its own I/O thread. publish(), time() and new_session() are
// called from one producer thread (the simulation, a replay, a DDS relay); they only copy into
// the subscribed clients' queues, so a slow or stalled client never slows the producer or the
// other clients.
class Server {
 public:
  // Listens and starts the I/O thread. Errors: a bad address, a port in use.
  static Result<std::unique_ptr<Server>> start(const ServerOptions& options,
                                               std::vector<ChannelSpec> channels);
  ~Server();  // stop()
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  std::uint16_t port() const;  // the port listened on (the chosen one for port 0)
  const std::vector<ChannelSpec>& channels() const;
  // A new session (a scene start, a --loop pass, a new scene in a relay): every client gets a
  // serverInfo with a new sessionId (Foxglove then clears what it has shown), and the latched
  // messages of the old session are forgotten.
  void new_session();
  // True when some client subscribes to `channel` (cheap: lets a producer skip encoding).
  bool subscribed(ChannelId channel) const;
  // Queues a message for the subscribers of `channel` (1-based); a latched channel also keeps it
  // for later subscriptions.
  void publish(ChannelId channel, std::uint64_t log_time_ns, std::span<const std::byte> payload);
  // Queues a time message for every client; the session's last one also goes to a client that
  // connects later (after the advertisements, before anything it subscribes to), so a viewer
  // joining a paused stream knows where it stands.
  void time(std::uint64_t time_ns);
  std::size_t client_count() const;
  ServerStats stats() const;
  // Waits until every client has been handed everything queued for it and the socket layer has
  // written it (or `timeout_s` passed, or the clients are gone): the end of a run reaches viewers
  // that keep up before the server closes. True when everything went out.
  bool flush(double timeout_s);
  // Closes every connection and joins the I/O thread (idempotent).
  void stop();

  struct Impl;

 private:
  Server() = default;
  std::unique_ptr<Impl> impl_;
};

// The channels of `topics` (msgs::topics() order) under namespace `ns`: encoding cdr, schema the
// ros2msg text rosbag2 writes, latched = transient local. `ids[topic id]` receives the channel id
// (0 for a topic not selected).
Result<std::vector<ChannelSpec>> ros2_channels(const msgs::TopicSet& topics, std::string_view ns,
                                               std::vector<ChannelId>* ids = nullptr);

// ---------------------------------------------------------------------------------------------
// The sink

struct SinkOptions {
  msgs::TopicSet topics = msgs::default_topics();
  std::string ns = "rbsim";        // the namespace of the frames in /tf and the markers
  std::int64_t publish_every = 1;  // every k-th step (as DdsSink)
  // Shared with the other sinks of a run (the node's DdsSink), so each step is encoded once; when
  // null the sink encodes for itself.
  std::shared_ptr<msgs::StepMessages> messages;
};

// Publishes a run into a Server started with ros2_channels(options.topics, ns): at begin() a new
// session and every selected latched topic; at each published step the time and every selected
// per-step topic that has a subscriber (nothing is encoded for a channel nobody watches). It does
// not pace: in rbsim node the Pacer before it in the driver releases every step at --rate.
class FoxgloveSink final : public Sink {
 public:
  FoxgloveSink(Server& server, std::vector<ChannelId> ids, const SinkOptions& options);
  Status begin(const Scene& scene, const World& world) override;
  Status write(const World& world) override;
  // Flushes the server (bounded, 2 s): viewers that keep up get the last steps.
  Status finish() override;
  // Bodies came or went: the scene description and markers again (latched; the markers start
  // with a DELETEALL, so the 3D panel drops what went), then the current step's per-step topics
  // at once, so a paused run shows the change without stepping.
  bool follows_structure() const override { return true; }
  Status restructure(const World& world, const Entities& entities) override;
  // A live change (a control command, between steps); values < 1 are taken as 1.
  void set_publish_every(std::int64_t every) { options_.publish_every = every < 1 ? 1 : every; }

 private:
  void publish(const msgs::TopicSpec& spec, const World& world);
  void publish_step(const World& world);
  Server* server_;
  std::vector<ChannelId> ids_;  // by TopicId
  SinkOptions options_;
  std::shared_ptr<msgs::StepMessages> messages_;
};

}  // namespace rbsim::foxglove
