// Service introspection's messages (REP 2012): what a service publishes on
// "<service name>/_service_event" when introspection is on. The type is rosidl's "pkg/srv/Name_Event":
// service_msgs/msg/ServiceEventInfo info, then the request and the response each as a sequence of at
// most one (empty but for a REQUEST_* event's request and a RESPONSE_* event's response, and empty
// then too when only metadata is published).
//
// Embedding a request in its event moves it to another offset of another message, so its 8-byte
// fields may need other padding: the bytes are never copied as they are, every value is re-aligned
// by msgs's schema-driven walk (MessageDecoder::copy) from the service's shipped definition.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "rbsim/msgs.hpp"

namespace rbsim::msgs {

// service_msgs/msg/ServiceEventInfo's event_type values.
enum class ServiceEventType : std::uint8_t {
  RequestSent = 0,
  RequestReceived = 1,
  ResponseSent = 2,
  ResponseReceived = 3,
};

// service_msgs/msg/ServiceEventInfo.
struct ServiceEventInfo {
  static constexpr std::string_view kType = "service_msgs/msg/ServiceEventInfo";
  ServiceEventType event_type = ServiceEventType::RequestSent;
  Time stamp;
  std::array<std::uint8_t, 16> client_gid{};  // char[16]
  std::int64_t sequence_number = 0;
  bool operator==(const ServiceEventInfo&) const = default;
};

// What a service publishes (rcl_service_introspection_state_t): nothing, the events without the
// request and response, or with them.
enum class IntrospectionState : std::uint8_t { Off, Metadata, Contents };
// The words of ROS 2's introspection demos and their string parameter
// "service_configure_introspection": "disabled", "metadata", "contents".
std::string_view to_string(IntrospectionState state);
std::optional<IntrospectionState> parse_introspection_state(std::string_view text);

// The topic suffix: events of service "/rbsim/pause" go to "/rbsim/pause/_service_event" (rcl's
// RCL_SERVICE_INTROSPECTION_TOPIC_POSTFIX).
inline constexpr std::string_view kServiceEventTopicSuffix = "/_service_event";
// "pkg/srv/Name" -> "pkg/srv/Name_Event".
std::string service_event_type(std::string_view srv_type);

// Encodes and decodes the events of one service type.
class ServiceEventCodec {
 public:
  // For "pkg/srv/Name", a service whose definition msgs ships; fails otherwise.
  static Result<ServiceEventCodec> create(std::string_view srv_type);

  // The event `info` with the request and the response given as whole CDR messages (header
  // included, as a service handler sees them), either empty for an empty sequence. Fails, `out`
  // then unusable, when a given message does not read as its type.
  [[nodiscard]] Status encode(const ServiceEventInfo& info, std::span<const std::byte> request,
                              std::span<const std::byte> response, Bytes& out) const;
  // An event back: its info, and the request and the response as whole CDR messages of their own
  // (re-aligned back; cleared when the sequence is empty). Fails on malformed data (a sequence
  // longer than 1, a truncated value, a wrong header).
  [[nodiscard]] Status decode(std::span<const std::byte> cdr, ServiceEventInfo& info, Bytes& request,
                              Bytes& response) const;
  const std::string& event_type() const { return event_type_; }

 private:
  ServiceEventCodec(MessageDecoder request, MessageDecoder response, std::string event_type)
      : request_(std::move(request)), response_(std::move(response)), event_type_(std::move(event_type)) {}
  MessageDecoder request_, response_;
  std::string event_type_;
};

}  // namespace rbsim::msgs
