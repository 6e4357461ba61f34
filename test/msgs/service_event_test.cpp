// Service introspection's events (rbsim/service_event.hpp) and the one CDR re-aligner under them
// (MessageDecoder::copy): a request or response struct encoded by its own codec, embedded in its
// _Event, read back at its real offset by the schema-driven decoder of the _Event type and by the
// codec's decode (re-aligned back, then the struct codec), each compared with what was sent. The
// types hold float64 and int64 after odd-sized fields, strings, sequences and nested messages;
// string lengths vary so the embedded value lands at every alignment.
#include "rbsim/service_event.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <concepts>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "rbsim/cdr.hpp"
#include "rbsim/interfaces.hpp"
#include "rbsim/simulation_interfaces.hpp"

namespace rbsim::msgs {
namespace {

ServiceEventInfo info_of(ServiceEventType type, std::int64_t seq) {
  ServiceEventInfo info;
  info.event_type = type;
  info.stamp = {1700000000, 123456789};
  for (std::size_t i = 0; i < info.client_gid.size(); ++i)
    info.client_gid[i] = static_cast<std::uint8_t>(0xa0 + i);
  info.sequence_number = seq;
  return info;
}

// The schema-driven decoder of `type` (its ros2msg schema as a recording would hold it).
MessageDecoder decoder_of(const std::string& type) {
  Result<std::string> schema = ros2msg_schema(type);
  EXPECT_TRUE(schema) << type << ": " << (schema ? "" : schema.error().message);
  Result<MessageDecoder> d = MessageDecoder::create(type, schema.value());
  EXPECT_TRUE(d) << type << ": " << (d ? "" : d.error().message);
  return std::move(d.value());
}

// The scalars of ServiceEventInfo: event_type, stamp (2), client_gid (16), sequence_number.
constexpr std::size_t kInfoScalars = 20;

// The event's scalars as the _Event decoder reads them in place: the info, then the request
// sequence (its length, then the value's scalars), then the response sequence.
struct EventScalars {
  std::vector<Scalar> info, request, response;
};
EventScalars split_event(const MessageDecoder& event, std::span<const std::byte> cdr,
                         std::size_t request_scalars) {
  std::vector<Scalar> all;
  const Status st = event.decode(cdr, all);
  EXPECT_TRUE(st) << (st ? "" : st.error().message);
  EventScalars out;
  if (all.size() < kInfoScalars + 2) return out;
  out.info.assign(all.begin(), all.begin() + kInfoScalars);
  std::size_t at = kInfoScalars;
  const std::uint64_t has_request = all[at++].u;
  const std::size_t n = has_request == 1 ? request_scalars : 0;
  out.request.assign(all.begin() + static_cast<std::ptrdiff_t>(at),
                     all.begin() + static_cast<std::ptrdiff_t>(at + n));
  at += n;
  out.response.assign(all.begin() + static_cast<std::ptrdiff_t>(at + 1), all.end());
  return out;
}

// A struct decoded back equals the one sent: by value where the type compares, else by its bytes
// encoded again.
template <class T>
void expect_same(const T& got, const T& sent) {
  if constexpr (std::equality_comparable<T>) {
    EXPECT_TRUE(got == sent);
  }
  Bytes a, b;
  encode(got, a);
  encode(sent, b);
  EXPECT_EQ(a, b);
}

// Embeds `req` in a REQUEST_RECEIVED event and `res` in a RESPONSE_SENT one, and reads both back
// three ways: the schema decoder of the _Event in place, the codec's decode to bytes (equal to the
// struct codec's own bytes) and those bytes through the struct codec (equal to what was sent).
template <class Req, class Res>
void round_trip(const Req& req, const Res& res) {
  const std::string srv(Req::kService);
  Result<ServiceEventCodec> codec = ServiceEventCodec::create(srv);
  ASSERT_TRUE(codec) << codec.error().message;
  const MessageDecoder event = decoder_of(srv + "_Event");
  const MessageDecoder request_decoder = decoder_of(srv + "_Request");
  const MessageDecoder response_decoder = decoder_of(srv + "_Response");

  Bytes req_cdr, res_cdr, ev;
  encode(req, req_cdr);
  encode(res, res_cdr);
  std::vector<Scalar> req_scalars, res_scalars;
  ASSERT_TRUE(request_decoder.decode(req_cdr, req_scalars));
  ASSERT_TRUE(response_decoder.decode(res_cdr, res_scalars));

  // The request, in place.
  ASSERT_TRUE(codec.value().encode(info_of(ServiceEventType::RequestReceived, 7), req_cdr, {}, ev));
  EventScalars in_place = split_event(event, ev, req_scalars.size());
  EXPECT_EQ(in_place.request, req_scalars);
  EXPECT_TRUE(in_place.response.empty());
  EXPECT_EQ(in_place.info[0].u, 1u);     // REQUEST_RECEIVED
  EXPECT_EQ(in_place.info[19].i, 7);     // sequence_number
  EXPECT_EQ(in_place.info[3].u, 0xa0u);  // client_gid[0]
  // ... and back as a message of its own, then as the struct.
  ServiceEventInfo info;
  Bytes back_req, back_res;
  ASSERT_TRUE(codec.value().decode(ev, info, back_req, back_res));
  EXPECT_EQ(info, info_of(ServiceEventType::RequestReceived, 7));
  EXPECT_EQ(back_req, req_cdr);
  EXPECT_TRUE(back_res.empty());
  Req req_back;
  ASSERT_TRUE(decode(back_req, req_back));
  expect_same(req_back, req);

  // The response.
  ASSERT_TRUE(codec.value().encode(info_of(ServiceEventType::ResponseSent, 8), {}, res_cdr, ev));
  in_place = split_event(event, ev, 0);
  EXPECT_EQ(in_place.response, res_scalars);
  EXPECT_TRUE(in_place.request.empty());
  ASSERT_TRUE(codec.value().decode(ev, info, back_req, back_res));
  EXPECT_EQ(info.event_type, ServiceEventType::ResponseSent);
  EXPECT_TRUE(back_req.empty());
  EXPECT_EQ(back_res, res_cdr);
  Res res_back;
  ASSERT_TRUE(decode(back_res, res_back));
  expect_same(res_back, res);
}

ParameterValue full_value(std::size_t text) {
  ParameterValue v;
  v.type = ParameterType::DoubleArray;
  v.bool_value = true;
  v.integer_value = -1234567890123;  // int64 after uint8 type and bool
  v.double_value = -0.0;
  v.string_value = std::string(text, 's');
  v.byte_array_value = {0, 255, 7};
  v.bool_array_value = {true, false, true};
  v.integer_array_value = {INT64_MIN, 0, INT64_MAX};
  v.double_array_value = {1.5, std::numeric_limits<double>::quiet_NaN(),
                          -std::numeric_limits<double>::infinity()};
  v.string_array_value = {"", "a", std::string(text + 1, 'x')};
  return v;
}

TEST(ServiceEventCodec, SetParametersRoundTripsAtEveryAlignment) {
  for (std::size_t len = 0; len < 9; ++len) {  // the name's length moves what follows through every alignment
    SCOPED_TRACE("name length " + std::to_string(len));
    SetParametersRequest req;
    req.parameters.push_back({std::string(len, 'n'), full_value(len)});
    req.parameters.push_back({"rate", ParameterValue::of_double(2.5)});
    SetParametersResponse res;
    res.results = {{true, ""}, {false, std::string(len, 'r')}};
    // The NaN does not compare equal as a struct: compare the rest, the bytes cover the NaN.
    req.parameters[0].value.double_array_value[1] = 3.25;
    round_trip(req, res);
  }
}

TEST(ServiceEventCodec, SetEntityStateRoundTripsWithFloat64AfterStrings) {
  for (std::size_t len = 0; len < 9; ++len) {
    SCOPED_TRACE("entity length " + std::to_string(len));
    simulation::SetEntityStateRequest req;
    req.entity = "body_" + std::string(len, '7');
    req.state.stamp = {3, 500};
    req.state.frame_id = std::string(len + 3, 'f');
    req.state.position = {1.25, -2.5, 0.0};
    req.state.orientation = {0.0, 0.0, std::sin(0.3), std::cos(0.3)};
    req.state.linear_velocity = {1e-300, -1e300, 4.0};
    req.set_pose = true;
    req.set_twist = true;
    simulation::SetEntityStateResponse res;
    res.result.result = simulation::Result::kOk;
    res.result.error_message = std::string(len, 'e');
    round_trip(req, res);
  }
}

TEST(ServiceEventCodec, TriggerAndStepRoundTrip) {
  round_trip(TriggerRequest{}, TriggerResponse{true, "paused at step 12"});
  StepRequest step;
  step.steps = 5;
  StepResponse answered;
  answered.success = true;
  answered.message = "odd";
  answered.step = 123456789012;  // a uint64 after a string of odd length
  round_trip(step, answered);
}

// The test can fail: the request's bytes copied as they are (no re-alignment) put an int64 four
// bytes off, and the in-place decoder then reads other values.
TEST(ServiceEventCodec, CopyingTheBytesAsTheyAreWouldMisalign) {
  SetParametersRequest req;
  req.parameters.push_back({"ab", ParameterValue::of_integer(0x0102030405060708)});
  Bytes req_cdr, good;
  encode(req, req_cdr);
  Result<ServiceEventCodec> codec = ServiceEventCodec::create(SetParametersRequest::kService);
  ASSERT_TRUE(codec);
  ASSERT_TRUE(codec.value().encode(info_of(ServiceEventType::RequestReceived, 1), req_cdr, {}, good));
  // The naive event: the info and the sequence length as the codec wrote them, then the bytes.
  const std::size_t body_at = CdrCursor::kHeader + 44;  // info (40 bytes) + the sequence length
  Bytes naive(good.begin(), good.begin() + static_cast<std::ptrdiff_t>(body_at));
  naive.insert(naive.end(), req_cdr.begin() + CdrCursor::kHeader, req_cdr.end());
  for (int i = 0; i < 4; ++i) naive.push_back(std::byte{0});  // the response: empty
  EXPECT_NE(naive, good);
  ServiceEventInfo info;
  Bytes back_req, back_res;
  SetParametersRequest got;
  const Status st = codec.value().decode(naive, info, back_req, back_res);
  EXPECT_TRUE(!st || !decode(back_req, got) || !(got == req));
}

TEST(ServiceEventCodec, MetadataEventsHoldEmptySequences) {
  Result<ServiceEventCodec> codec = ServiceEventCodec::create(TriggerRequest::kService);
  ASSERT_TRUE(codec);
  EXPECT_EQ(codec.value().event_type(), "std_srvs/srv/Trigger_Event");
  Bytes ev;
  ASSERT_TRUE(codec.value().encode(info_of(ServiceEventType::ResponseSent, 3), {}, {}, ev));
  // header, info (40 bytes), two zero lengths: 4 + 48 bytes, a multiple of 4.
  EXPECT_EQ(ev.size(), 52u);
  ServiceEventInfo info;
  Bytes req{std::byte{1}}, res{std::byte{1}};
  ASSERT_TRUE(codec.value().decode(ev, info, req, res));
  EXPECT_EQ(info, info_of(ServiceEventType::ResponseSent, 3));
  EXPECT_TRUE(req.empty());
  EXPECT_TRUE(res.empty());
}

TEST(ServiceEventCodec, RefusesMalformedInput) {
  Result<ServiceEventCodec> codec = ServiceEventCodec::create(SetParametersRequest::kService);
  ASSERT_TRUE(codec);
  SetParametersRequest req;
  req.parameters.push_back({"name", full_value(3)});
  Bytes req_cdr, ev;
  encode(req, req_cdr);
  const ServiceEventInfo info = info_of(ServiceEventType::RequestReceived, 1);
  // Every truncation of the request is refused, never read past its end.
  for (std::size_t n = CdrCursor::kHeader; n + 4 <= req_cdr.size(); ++n) {
    EXPECT_FALSE(codec.value().encode(info, std::span(req_cdr).first(n), {}, ev)) << n;
  }
  Bytes big_endian = req_cdr;
  big_endian[1] = std::byte{0};
  EXPECT_FALSE(codec.value().encode(info, big_endian, {}, ev));
  // Every truncation of an event is refused by decode.
  ASSERT_TRUE(codec.value().encode(info, req_cdr, {}, ev));
  ServiceEventInfo got;
  Bytes a, b;
  for (std::size_t n = 0; n + 4 <= ev.size(); ++n) {
    EXPECT_FALSE(codec.value().decode(std::span(ev).first(n), got, a, b)) << n;
  }
  // A request sequence of two, and an unknown event type.
  Bytes two = ev;
  two[CdrCursor::kHeader + 40] = std::byte{2};
  EXPECT_FALSE(codec.value().decode(two, got, a, b));
  Bytes bad_type = ev;
  bad_type[CdrCursor::kHeader] = std::byte{4};
  EXPECT_FALSE(codec.value().decode(bad_type, got, a, b));
}

TEST(ServiceEventCodec, CreateRefusesUnknownServices) {
  EXPECT_FALSE(ServiceEventCodec::create("std_srvs/srv/NoSuchService"));
  EXPECT_FALSE(ServiceEventCodec::create("std_msgs/msg/Header"));
  EXPECT_EQ(service_event_type("std_srvs/srv/Trigger"), "std_srvs/srv/Trigger_Event");
}

TEST(Ros2msgSchema, DescribesAServiceEventAndItsParts) {
  Result<std::string> schema = ros2msg_schema("std_srvs/srv/Trigger_Event");
  ASSERT_TRUE(schema) << schema.error().message;
  const std::string& s = schema.value();
  EXPECT_TRUE(
      s.starts_with("service_msgs/ServiceEventInfo info\nstd_srvs/srv/Trigger_Request[<=1] request\n"
                    "std_srvs/srv/Trigger_Response[<=1] response\n"))
      << s;
  EXPECT_NE(s.find("\nMSG: service_msgs/ServiceEventInfo\n"), std::string::npos);
  EXPECT_NE(s.find("\nMSG: builtin_interfaces/Time\n"), std::string::npos);
  EXPECT_NE(s.find("\nMSG: std_srvs/srv/Trigger_Request\n"), std::string::npos);
  EXPECT_NE(s.find("\nMSG: std_srvs/srv/Trigger_Response\nbool success"), std::string::npos);
  Result<std::string> request = ros2msg_schema("rcl_interfaces/srv/SetParameters_Request");
  ASSERT_TRUE(request);
  EXPECT_NE(request.value().find("\nMSG: rcl_interfaces/Parameter\n"), std::string::npos) << request.value();
  EXPECT_FALSE(ros2msg_schema("std_srvs/srv/NoSuch_Event"));
}

}  // namespace
}  // namespace rbsim::msgs
