// clientPublish without a network: a client's advertise / unadvertise of <node>/command_in
// channels (only that topic, schema and the encodings cdr and json; a bound on channels), its
// messageData frames handed over with their channel's encoding, every malformed form answered with
// a status error; and decode_command: the CDR and JSON forms of rbsim_msgs/msg/Command as the
// same Command, the names of the node's parameters checked, malformed payloads refused.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cstring>
#include <string>
#include <unordered_map>

#include "../../tools/foxglove/src/services.hpp"
#include "rbsim/foxglove.hpp"

namespace rbsim::foxglove {
namespace {

using Json = nlohmann::json;

std::string le32(std::uint32_t v) {
  std::string s(4, '\0');
  std::memcpy(s.data(), &v, 4);
  return s;
}
std::string message_frame(std::uint32_t channel, const std::string& payload) {
  return "\x01" + le32(channel) + payload;
}
std::string advertise(std::uint32_t id, const std::string& topic, const std::string& encoding,
                      const std::string& schema = "rbsim_msgs/msg/Command") {
  return Json{{"op", "advertise"},
              {"channels",
               Json::array({{{"id", id}, {"topic", topic}, {"encoding", encoding}, {"schemaName", schema}}})}}
      .dump();
}
std::string error_of(const ClientProtocol::Outcome& o) {
  if (o.replies.size() != 1) return "(" + std::to_string(o.replies.size()) + " replies)";
  const Json j = Json::parse(o.replies[0]);
  EXPECT_EQ(j["level"], 2);
  return j["message"];
}
bool has(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

TEST(FoxgloveClientPublish, OnlyWithAcceptPublishAreClientChannelsTaken) {
  ClientProtocol off(1, true, 5);
  ClientProtocol::Outcome o;
  off.handle_text(advertise(1, "/sim/command_in", "cdr"), o);
  EXPECT_TRUE(has(error_of(o), "not supported")) << error_of(o);
  EXPECT_EQ(off.client_channel_count(), 0u);
  off.handle_binary(message_frame(1, "x"), o);
  EXPECT_FALSE(o.published);
  EXPECT_TRUE(has(error_of(o), "no client publishing")) << error_of(o);
}

TEST(FoxgloveClientPublish, AdvertisedChannelsCarryMessagesWithTheirEncoding) {
  ClientProtocol p(1, true, 5);
  p.accept_publish("/sim/command_in");
  ClientProtocol::Outcome o;
  p.handle_text(advertise(7, "/sim/command_in", "cdr"), o);
  EXPECT_TRUE(o.replies.empty()) << o.replies[0];
  p.handle_text(advertise(8, "/sim/command_in", "json"), o);
  EXPECT_TRUE(o.replies.empty());
  EXPECT_EQ(p.client_channel_count(), 2u);
  p.handle_binary(message_frame(7, std::string("\0\1\2", 3)), o);
  ASSERT_TRUE(o.published);
  EXPECT_TRUE(o.replies.empty());
  EXPECT_EQ(o.published->channel, 7u);
  EXPECT_EQ(o.published->encoding, "cdr");
  EXPECT_EQ(o.published->payload, std::string("\0\1\2", 3));
  p.handle_binary(message_frame(8, "{}"), o);
  ASSERT_TRUE(o.published);
  EXPECT_EQ(o.published->encoding, "json");
  // Unadvertised: its messages are refused, the other channel stays.
  p.handle_text(R"({"op":"unadvertise","channelIds":[7]})", o);
  EXPECT_TRUE(o.replies.empty());
  p.handle_binary(message_frame(7, "x"), o);
  EXPECT_FALSE(o.published);
  EXPECT_TRUE(has(error_of(o), "unknown channel 7")) << error_of(o);
  p.handle_binary(message_frame(8, "{}"), o);
  EXPECT_TRUE(o.published);
  // Service calls still work beside it.
  p.handle_binary("\x02" + le32(1) + le32(1) + le32(3) + "cdr", o);
  EXPECT_TRUE(o.call);
}

TEST(FoxgloveClientPublish, EveryOtherAdvertisementAndFrameIsRefusedWithAStatusError) {
  ClientProtocol p(1, true, 5);
  p.accept_publish("/sim/command_in");
  ClientProtocol::Outcome o;
  const std::pair<std::string, std::string> cases[] = {
      {advertise(1, "/sim/commands", "cdr"), "takes /sim/command_in only"},
      {advertise(1, "/sim/command_in", "ros1"), "encoding \"ros1\" refused"},
      {advertise(1, "/sim/command_in", "cdr", "std_msgs/msg/String"), "schemaName"},
      {R"({"op":"advertise","channels":[{"topic":"/sim/command_in"}]})", "needs an integer \"id\""},
      {R"({"op":"advertise","channels":[{"id":-1}]})", "needs an integer \"id\""},
      {R"({"op":"advertise","channels":[7]})", "needs an integer \"id\""},
      {R"({"op":"advertise","channels":{}})", "\"channels\" must be an array"},
      {R"({"op":"unadvertise","channelIds":[99]})", "unknown client channel 99"},
      {R"({"op":"unadvertise","channelIds":["a"]})", "not a channel id"},
      {R"({"op":"unadvertise"})", "\"channelIds\" must be an array"},
  };
  for (const auto& [frame, says] : cases) {
    p.handle_text(frame, o);
    EXPECT_TRUE(has(error_of(o), says)) << frame << " -> " << error_of(o);
    EXPECT_EQ(p.client_channel_count(), 0u) << frame;
  }
  p.handle_text(advertise(1, "/sim/command_in", "cdr"), o);
  p.handle_text(advertise(1, "/sim/command_in", "json"), o);
  EXPECT_TRUE(has(error_of(o), "already advertised")) << error_of(o);
  // Binary frames: too short, unknown channel, over the limit.
  p.handle_binary(std::string("\x01\x01\x00", 3), o);
  EXPECT_TRUE(has(error_of(o), "header alone")) << error_of(o);
  p.handle_binary(message_frame(2, "x"), o);
  EXPECT_TRUE(has(error_of(o), "unknown channel 2")) << error_of(o);
  p.handle_binary(message_frame(1, std::string(kMaxClientFrame, 'x')), o);
  EXPECT_FALSE(o.published);
  EXPECT_TRUE(has(error_of(o), "the limit is")) << error_of(o);
}

TEST(FoxgloveClientPublish, ClientChannelsAreBounded) {
  ClientProtocol p(1, true, 5);
  p.accept_publish("/n/command_in");
  ClientProtocol::Outcome o;
  Json channels = Json::array();
  for (std::uint32_t id = 1; id <= kMaxClientChannels + 5; ++id) {
    channels.push_back({{"id", id},
                        {"topic", "/n/command_in"},
                        {"encoding", "cdr"},
                        {"schemaName", "rbsim_msgs/msg/Command"}});
  }
  p.handle_text(Json{{"op", "advertise"}, {"channels", channels}}.dump(), o);
  EXPECT_EQ(p.client_channel_count(), kMaxClientChannels);
  EXPECT_TRUE(has(error_of(o), "at most " + std::to_string(kMaxClientChannels))) << error_of(o);
}

// decode_command

const std::unordered_map<std::string, std::size_t> kKnown = {{"forces.0.fy", 0}, {"paused", 1}};

TEST(FoxgloveCommandIn, CdrAndJsonGiveTheSameCommand) {
  msgs::CommandMessage m;
  m.seq = 42;
  m.step = 99;  // ignored: a live command applies at the next boundary
  m.kind = msgs::CommandMessage::SetParameters;
  m.source = "client";
  m.atomic = false;
  m.parameters = {{"forces.0.fy", msgs::ParameterValue::of_double(-2.5)}};
  Bytes cdr;
  msgs::encode(m, cdr);
  auto a = detail::decode_command("cdr", {reinterpret_cast<const char*>(cdr.data()), cdr.size()}, kKnown);
  ASSERT_TRUE(a) << a.error().message;
  auto b = detail::decode_command("json",
                                  R"({"seq":42,"step":99,"kind":0,"source":"client","atomic":false,
          "parameters":[{"name":"forces.0.fy","value":{"type":3,"double_value":-2.5}}]})",
                                  kKnown);
  ASSERT_TRUE(b) << b.error().message;
  for (const auto* c : {&a.value(), &b.value()}) {
    EXPECT_EQ(c->kind, control::CommandKind::SetParameters);
    EXPECT_EQ(c->step, 0);
    EXPECT_FALSE(c->atomic);
    ASSERT_EQ(c->parameters.size(), 1u);
    EXPECT_EQ(c->parameters[0].name, "forces.0.fy");
    EXPECT_EQ(c->parameters[0].value, msgs::ParameterValue::of_double(-2.5));
  }
  auto impulse = detail::decode_command("json", R"({"kind":5,"body":1,"jx":2.5,"jy":-1,"py":0.25})", kKnown);
  ASSERT_TRUE(impulse) << impulse.error().message;
  EXPECT_EQ(impulse->kind, control::CommandKind::Impulse);
  EXPECT_EQ(impulse->impulse.body, 1);
  EXPECT_EQ(impulse->impulse.impulse, Vec2(2.5, -1.0));
  EXPECT_EQ(impulse->impulse.point, Vec2(0.0, 0.25));
  auto steps = detail::decode_command("json", R"({"kind":3,"steps":4})", kKnown);
  ASSERT_TRUE(steps);
  EXPECT_EQ(steps->steps, 4);
  auto arrays = detail::decode_command(
      "json", R"({"parameters":[{"name":"paused","value":{"type":6,"bool_array_value":[true,false]}}]})",
      kKnown);
  ASSERT_TRUE(arrays) << arrays.error().message;
  EXPECT_EQ(arrays->parameters[0].value.bool_array_value, (std::vector<bool>{true, false}));
}

TEST(FoxgloveCommandIn, MalformedPayloadsAreRefusedWithTheirReason) {
  const std::pair<std::string, std::string> json_cases[] = {
      {"", "not a JSON object"},
      {"[1]", "not a JSON object"},
      {"{\"kind\":", "not a JSON object"},
      {R"({"kind":13})", "unknown kind 13"},
      {R"({"kind":9})", "delete_entity: parameter 'name' missing"},
      {R"({"kind":-1})", "'kind' must be an integer"},
      {R"({"kind":256})", "'kind' must be an integer"},
      {R"({"body":"one"})", "'body' must be an integer"},
      {R"({"jx":"1"})", "'jx' must be a number"},
      {R"({"atomic":1})", "'atomic' must be true or false"},
      {R"({"steps":1e3})", "'steps' must be an integer"},
      {R"({"steps":18446744073709551615})", "past the int64 range"},
      {R"({"bogus":1})", "no field 'bogus'"},
      {R"({"parameters":{}})", "'parameters' must be an array"},
      {R"({"parameters":[1]})", "parameters[0]: not an object"},
      {R"({"parameters":[{"name":"nope"}]})", "no parameter 'nope'"},
      {R"({"parameters":[{"name":"paused","value":{"type":1,"colour":1}}]})", "no field 'colour'"},
      {R"({"parameters":[{"name":"paused","value":{"double_array_value":[1,"x"]}}]})",
       "an array of a number"},
      {R"({"parameters":[{"name":"paused"},{"name":"paused"},{"name":"paused"}]})", "more than the node's 2"},
      {std::string(100000, '[') + std::string(100000, ']'), "nested deeper"},
  };
  for (const auto& [payload, says] : json_cases) {
    auto r = detail::decode_command("json", payload, kKnown);
    ASSERT_FALSE(r) << payload;
    EXPECT_TRUE(has(r.error().message, says)) << payload.substr(0, 80) << " -> " << r.error().message;
  }
  for (const std::string& payload :
       {std::string(), std::string("\x00\x01\x00\x00", 4), std::string(3000, '\xff')}) {
    EXPECT_FALSE(detail::decode_command("cdr", payload, kKnown)) << payload.size();
  }
  msgs::CommandMessage m;
  m.parameters = {{"nope", msgs::ParameterValue::of_double(1.0)}};
  Bytes cdr;
  msgs::encode(m, cdr);
  auto r = detail::decode_command("cdr", {reinterpret_cast<const char*>(cdr.data()), cdr.size()}, kKnown);
  ASSERT_FALSE(r);
  EXPECT_TRUE(has(r.error().message, "no parameter 'nope'")) << r.error().message;
}

}  // namespace
}  // namespace rbsim::foxglove
