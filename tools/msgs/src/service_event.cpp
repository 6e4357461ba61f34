// Service introspection's event messages (rbsim/service_event.hpp).
#include "rbsim/service_event.hpp"

#include "cdr.hpp"
#include "rbsim/cdr.hpp"

namespace rbsim::msgs {

std::string_view to_string(IntrospectionState state) {
  switch (state) {
    case IntrospectionState::Off:
      return "disabled";
    case IntrospectionState::Metadata:
      return "metadata";
    case IntrospectionState::Contents:
      return "contents";
  }
  return "disabled";
}

std::optional<IntrospectionState> parse_introspection_state(std::string_view text) {
  for (const IntrospectionState s :
       {IntrospectionState::Off, IntrospectionState::Metadata, IntrospectionState::Contents}) {
    if (text == to_string(s)) return s;
  }
  return std::nullopt;
}

std::string service_event_type(std::string_view srv_type) {
  return std::string(srv_type) + std::string(kServiceEventSuffix);
}

namespace {
Result<MessageDecoder> part_decoder(std::string_view srv_type, std::string_view suffix) {
  const std::string type = std::string(srv_type) + std::string(suffix);
  Result<std::string> schema = ros2msg_schema(type);
  if (!schema) return with_context(type + ": ", schema.error());
  return MessageDecoder::create(type, schema.value());
}

// One sequence of at most one `part`: its length, then the value re-aligned; empty `message`:
// length 0.
Status put_part(const MessageDecoder& part, std::span<const std::byte> message, detail::CdrWriter& w) {
  if (message.empty()) {
    w.sequence_length(0);
    return Ok{};
  }
  if (!CdrCursor::plain_header(message))
    return Error{"not a plain little-endian CDR message (header 00 01)", ErrorCode::InvalidArgument};
  w.sequence_length(1);
  CdrCursor from(message);
  return part.copy(from, w);
}

// The sequence of at most one `part` at `at`, as a message of its own in `out` (cleared when empty).
Status get_part(const MessageDecoder& part, CdrCursor& at, Bytes& out, const char* name) {
  std::uint32_t n = 0;
  if (!at.u32(n)) return Error{std::string("truncated before the ") + name};
  if (n > 1)
    return Error{std::string("the ") + name + " sequence holds " + std::to_string(n) + " (at most 1)"};
  out.clear();
  if (n == 0) return Ok{};
  detail::CdrWriter w(out);
  return part.copy(at, w);
}
}  // namespace

Result<ServiceEventCodec> ServiceEventCodec::create(std::string_view srv_type) {
  if (srv_type.find("/srv/") == std::string_view::npos || definition(srv_type).empty())
    return Error{"\"" + std::string(srv_type) + "\" is not a service rbsim carries (pkg/srv/Name)"};
  Result<MessageDecoder> request = part_decoder(srv_type, kServiceRequestSuffix);
  if (!request) return request.error();
  Result<MessageDecoder> response = part_decoder(srv_type, kServiceResponseSuffix);
  if (!response) return response.error();
  return ServiceEventCodec(std::move(request.value()), std::move(response.value()),
                           service_event_type(srv_type));
}

Status ServiceEventCodec::encode(const ServiceEventInfo& info, std::span<const std::byte> request,
                                 std::span<const std::byte> response, Bytes& out) const {
  detail::CdrWriter w(out);
  w.u8(static_cast<std::uint8_t>(info.event_type));
  w.time(info.stamp);
  for (const std::uint8_t b : info.client_gid) w.u8(b);
  w.i64(info.sequence_number);
  if (Status st = put_part(request_, request, w); !st)
    return with_context(event_type_ + ": request: ", st.error());
  if (Status st = put_part(response_, response, w); !st)
    return with_context(event_type_ + ": response: ", st.error());
  return Ok{};
}

Status ServiceEventCodec::decode(std::span<const std::byte> cdr, ServiceEventInfo& info, Bytes& request,
                                 Bytes& response) const {
  if (!CdrCursor::plain_header(cdr))
    return Error{event_type_ + ": not a plain little-endian CDR message (header 00 01)"};
  CdrCursor at(cdr);
  std::uint8_t type = 0;
  ServiceEventInfo got;
  bool ok = at.read(type) && at.read(got.stamp.sec) && at.read(got.stamp.nanosec);
  for (std::uint8_t& b : got.client_gid) ok = ok && at.read(b);
  ok = ok && at.read(got.sequence_number);
  if (!ok) return Error{event_type_ + ": truncated in its info"};
  if (type > static_cast<std::uint8_t>(ServiceEventType::ResponseReceived))
    return Error{event_type_ + ": event_type " + std::to_string(type) + " is none of ServiceEventInfo's"};
  got.event_type = static_cast<ServiceEventType>(type);
  if (Status st = get_part(request_, at, request, "request"); !st)
    return with_context(event_type_ + ": ", st.error());
  if (Status st = get_part(response_, at, response, "response"); !st)
    return with_context(event_type_ + ": ", st.error());
  info = got;
  return Ok{};
}

}  // namespace rbsim::msgs
