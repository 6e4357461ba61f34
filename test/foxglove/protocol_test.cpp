// The Foxglove protocol core and the per-client queue, without a network: every client op, every
// hostile input the issue lists, subscription bookkeeping, the subprotocol choice, and the flow
// control rules (queue bound, oldest per-step dropped, latched never, one warning per burst).
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cstring>
#include <set>
#include <string>
#include <vector>

#include "rbsim/foxglove.hpp"

namespace rbsim::foxglove {
namespace {

using Json = nlohmann::json;

Json parsed(const std::string& text) {
  return Json::parse(text);
}

// The status replies of an outcome: (level, message).
std::vector<std::pair<int, std::string>> statuses(const ClientProtocol::Outcome& o) {
  std::vector<std::pair<int, std::string>> out;
  for (const std::string& r : o.replies) {
    const Json j = parsed(r);
    EXPECT_EQ(j.at("op"), "status") << r;
    out.emplace_back(j.at("level").get<int>(), j.at("message").get<std::string>());
  }
  return out;
}

std::vector<std::byte> bytes(std::string_view s) {
  std::vector<std::byte> b(s.size());
  std::memcpy(b.data(), s.data(), s.size());
  return b;
}

// ---------------------------------------------------------------------------------------------
// Subprotocols and server messages

TEST(FoxgloveProtocol, SubprotocolIsTheClientsChoiceAmongOurs) {
  using V = std::vector<std::string>;
  EXPECT_EQ(choose_subprotocol(V{"foxglove.websocket.v1"}), "foxglove.websocket.v1");
  EXPECT_EQ(choose_subprotocol(V{"foxglove.sdk.v1"}), "foxglove.sdk.v1");
  EXPECT_EQ(choose_subprotocol(V{"foxglove.websocket.v1", "foxglove.sdk.v1"}), "foxglove.websocket.v1");
  EXPECT_EQ(choose_subprotocol(V{"foxglove.sdk.v1", "foxglove.websocket.v1"}), "foxglove.sdk.v1");
  EXPECT_EQ(choose_subprotocol(V{"chat", "foxglove.sdk.v1"}), "foxglove.sdk.v1");
  EXPECT_EQ(choose_subprotocol(V{"chat"}), std::nullopt);
  EXPECT_EQ(choose_subprotocol(V{"foxglove.websocket.v2", "FOXGLOVE.SDK.V1"}), std::nullopt);
  EXPECT_EQ(choose_subprotocol(V{}), std::nullopt);
}

TEST(FoxgloveProtocol, ServerInfoHasTimeCapabilityAndSession) {
  const Json j = parsed(server_info_json("rbsim", "123-4"));
  EXPECT_EQ(j.at("op"), "serverInfo");
  EXPECT_EQ(j.at("name"), "rbsim");
  EXPECT_EQ(j.at("capabilities"), Json::array({"time"}));
  EXPECT_EQ(j.at("sessionId"), "123-4");
}

TEST(FoxgloveProtocol, AdvertiseListsEveryChannelWithOneBasedIds) {
  std::vector<ChannelSpec> channels(2);
  channels[0].topic = "/rbsim/scene";
  channels[0].schema_name = "rbsim_msgs/msg/SceneDescription";
  channels[0].schema = "string name\n";
  channels[1].topic = "/clock";
  channels[1].schema_name = "rosgraph_msgs/msg/Clock";
  channels[1].schema = "builtin_interfaces/Time clock\n";
  const Json j = parsed(advertise_json(channels));
  EXPECT_EQ(j.at("op"), "advertise");
  ASSERT_EQ(j.at("channels").size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    const Json& c = j.at("channels")[i];
    EXPECT_EQ(c.at("id"), i + 1);
    EXPECT_EQ(c.at("topic"), channels[i].topic);
    EXPECT_EQ(c.at("encoding"), "cdr");
    EXPECT_EQ(c.at("schemaName"), channels[i].schema_name);
    EXPECT_EQ(c.at("schema"), channels[i].schema);
    EXPECT_EQ(c.at("schemaEncoding"), "ros2msg");
  }
}

TEST(FoxgloveProtocol, RosChannelsCarryTheMcapSchemaAndLatchTransientLocalTopics) {
  std::vector<ChannelId> ids;
  auto channels = ros2_channels(msgs::default_topics(), "sim", &ids);
  ASSERT_TRUE(channels) << channels.error().message;
  ASSERT_EQ(channels.value().size(), msgs::default_topics().count());
  ASSERT_EQ(ids.size(), msgs::kTopicCount);
  for (const msgs::TopicSpec& spec : msgs::topics()) {
    const ChannelId id = ids[static_cast<std::size_t>(spec.id)];
    if (!msgs::default_topics().test(static_cast<std::size_t>(spec.id))) {
      EXPECT_EQ(id, 0u) << spec.suffix;
      continue;
    }
    ASSERT_GE(id, 1u);
    const ChannelSpec& c = channels.value()[id - 1];
    EXPECT_EQ(c.topic, msgs::topic_name(spec, "sim"));
    EXPECT_EQ(c.schema_name, spec.type);
    EXPECT_EQ(c.schema, msgs::ros2msg_schema(spec.type).value());
    EXPECT_EQ(c.latched, spec.transient_local);
  }
}

TEST(FoxgloveProtocol, StatusEscapesAndSurvivesInvalidUtf8) {
  const Json j = parsed(status_json(StatusLevel::Warning, "bad \"\xff\" byte\n"));
  EXPECT_EQ(j.at("level"), 1);
  EXPECT_NE(j.at("message").get<std::string>().find("bad"), std::string::npos);
}

TEST(FoxgloveProtocol, BinaryFramesAreLittleEndian) {
  std::string out;
  append_message_data(out, 0x01020304u, 0x1122334455667788ull, bytes("xyz"));
  const std::string want = std::string("\x01\x04\x03\x02\x01\x88\x77\x66\x55\x44\x33\x22\x11xyz", 16);
  EXPECT_EQ(out, want);
  out.clear();
  append_time(out, 1'500'000'000ull);
  ASSERT_EQ(out.size(), 9u);
  EXPECT_EQ(out[0], '\x02');
  std::uint64_t t = 0;
  std::memcpy(&t, out.data() + 1, 8);
  EXPECT_EQ(t, 1'500'000'000ull);
}

// ---------------------------------------------------------------------------------------------
// Client ops

TEST(FoxgloveClient, SubscribeAndUnsubscribe) {
  ClientProtocol p(3);
  ClientProtocol::Outcome o;
  p.handle_text(R"({"op":"subscribe","subscriptions":[{"id":7,"channelId":1},{"id":0,"channelId":3}]})", o);
  EXPECT_TRUE(o.replies.empty());
  ASSERT_EQ(o.subscribed.size(), 2u);
  EXPECT_EQ(o.subscribed[0], (ClientProtocol::Subscription{7, 1}));
  EXPECT_EQ(o.subscribed[1], (ClientProtocol::Subscription{0, 3}));
  EXPECT_EQ(p.subscription(1), 7u);
  EXPECT_EQ(p.subscription(2), std::nullopt);
  EXPECT_EQ(p.subscription(3), 0u);
  EXPECT_EQ(p.subscription_count(), 2u);

  p.handle_text(R"({"op":"unsubscribe","subscriptionIds":[7]})", o);
  EXPECT_TRUE(o.replies.empty());
  ASSERT_EQ(o.unsubscribed.size(), 1u);
  EXPECT_EQ(o.unsubscribed[0], (ClientProtocol::Subscription{7, 1}));
  EXPECT_EQ(p.subscription(1), std::nullopt);
  EXPECT_EQ(p.subscription_count(), 1u);

  // An id is free again once unsubscribed.
  p.handle_text(R"({"op":"subscribe","subscriptions":[{"id":7,"channelId":2}]})", o);
  EXPECT_TRUE(o.replies.empty());
  EXPECT_EQ(p.subscription(2), 7u);
}

TEST(FoxgloveClient, ExtraFieldsAreIgnored) {
  ClientProtocol p(1);
  ClientProtocol::Outcome o;
  p.handle_text(R"({"op":"subscribe","x":[1,2],"subscriptions":[{"id":1,"channelId":1,"extra":null}]})", o);
  EXPECT_TRUE(o.replies.empty());
  EXPECT_EQ(o.subscribed.size(), 1u);
}

TEST(FoxgloveClient, UnknownChannelAndReusedIdsAreErrorsAndTheRestStillApplies) {
  ClientProtocol p(2);
  ClientProtocol::Outcome o;
  p.handle_text(
      R"({"op":"subscribe","subscriptions":[{"id":1,"channelId":1},{"id":2,"channelId":9},{"id":1,"channelId":2},{"id":3,"channelId":1},{"id":4,"channelId":0}]})",
      o);
  ASSERT_EQ(o.subscribed.size(), 1u);
  EXPECT_EQ(o.subscribed[0], (ClientProtocol::Subscription{1, 1}));
  const auto s = statuses(o);
  ASSERT_EQ(s.size(), 1u) << "one status per frame";
  EXPECT_EQ(s[0].first, 2);
  EXPECT_NE(s[0].second.find("unknown channel 9"), std::string::npos) << s[0].second;
  EXPECT_NE(s[0].second.find("subscription id 1 is already in use"), std::string::npos) << s[0].second;
  EXPECT_NE(s[0].second.find("already subscribed to channel 1"), std::string::npos) << s[0].second;
  EXPECT_NE(s[0].second.find("unknown channel 0"), std::string::npos) << s[0].second;
  EXPECT_EQ(p.subscription_count(), 1u);
}

TEST(FoxgloveClient, UnknownSubscriptionIdIsAnError) {
  ClientProtocol p(2);
  ClientProtocol::Outcome o;
  p.handle_text(R"({"op":"subscribe","subscriptions":[{"id":5,"channelId":2}]})", o);
  p.handle_text(R"({"op":"unsubscribe","subscriptionIds":[6,5,5,"x",-1]})", o);
  ASSERT_EQ(o.unsubscribed.size(), 1u);
  EXPECT_EQ(o.unsubscribed[0].channel, 2u);
  const auto s = statuses(o);
  ASSERT_EQ(s.size(), 1u);
  EXPECT_EQ(s[0].first, 2);
  EXPECT_NE(s[0].second.find("unknown subscription 6"), std::string::npos) << s[0].second;
  EXPECT_NE(s[0].second.find("unknown subscription 5"), std::string::npos) << s[0].second;
  EXPECT_EQ(p.subscription_count(), 0u);
}

TEST(FoxgloveClient, ManyProblemsGiveOneBoundedStatus) {
  ClientProtocol p(1);
  std::string frame = R"({"op":"subscribe","subscriptions":[)";
  for (int i = 0; i < 10000; ++i) frame += (i ? "," : "") + std::string(R"({"id":1,"channelId":99})");
  frame += "]}";
  ClientProtocol::Outcome o;
  p.handle_text(frame, o);
  const auto s = statuses(o);
  ASSERT_EQ(s.size(), 1u);
  EXPECT_NE(s[0].second.find("and 9995 more"), std::string::npos) << s[0].second;
  EXPECT_LT(s[0].second.size(), 1000u);
}

struct Hostile {
  const char* name;
  std::string frame;
  const char* says;
};

class FoxgloveHostile : public ::testing::TestWithParam<Hostile> {};

TEST_P(FoxgloveHostile, GetsOneStatusErrorAndChangesNothing) {
  ClientProtocol p(3);
  ClientProtocol::Outcome o;
  p.handle_text(R"({"op":"subscribe","subscriptions":[{"id":1,"channelId":1}]})", o);
  ASSERT_EQ(p.subscription_count(), 1u);
  p.handle_text(GetParam().frame, o);
  EXPECT_TRUE(o.subscribed.empty());
  EXPECT_TRUE(o.unsubscribed.empty());
  const auto s = statuses(o);
  ASSERT_EQ(s.size(), 1u);
  EXPECT_EQ(s[0].first, 2);
  EXPECT_NE(s[0].second.find(GetParam().says), std::string::npos) << s[0].second;
  EXPECT_EQ(p.subscription(1), 1u);
  EXPECT_EQ(p.subscription_count(), 1u);
}

INSTANTIATE_TEST_SUITE_P(
    Inputs, FoxgloveHostile,
    ::testing::Values(
        Hostile{"Empty", "", "not valid JSON"}, Hostile{"Garbage", "{op:", "not valid JSON"},
        Hostile{"Truncated", R"({"op":"subscribe","subscriptions":[{"id":1)", "not valid JSON"},
        Hostile{"NotAnObject", "[1,2,3]", "not a JSON object"}, Hostile{"Number", "42", "not a JSON object"},
        Hostile{"NoOp", R"({"subscriptions":[]})", "no \"op\""},
        Hostile{"OpNotString", R"({"op":3})", "no \"op\""},
        Hostile{"UnknownOp", R"({"op":"explode"})", "unknown op"},
        Hostile{"ClientAdvertise", R"({"op":"advertise","channels":[]})", "not supported"},
        Hostile{"GetParameters", R"({"op":"getParameters","parameterNames":[]})", "not supported"},
        Hostile{"FetchAsset", R"({"op":"fetchAsset","uri":"file:///etc/passwd","requestId":1})",
                "not supported"},
        Hostile{"SubscriptionsNotArray", R"({"op":"subscribe","subscriptions":{"id":1}})",
                "must be an array"},
        Hostile{"IdsNotArray", R"({"op":"unsubscribe","subscriptionIds":1})", "must be an array"},
        Hostile{"NegativeId", R"({"op":"subscribe","subscriptions":[{"id":-1,"channelId":2}]})", "integer"},
        Hostile{"FloatId", R"({"op":"subscribe","subscriptions":[{"id":1.5,"channelId":2}]})", "integer"},
        Hostile{"HugeId", R"({"op":"subscribe","subscriptions":[{"id":4294967296,"channelId":2}]})",
                "integer"},
        Hostile{"StringChannel", R"({"op":"subscribe","subscriptions":[{"id":2,"channelId":"2"}]})",
                "integer"},
        Hostile{"EntryNotObject", R"({"op":"subscribe","subscriptions":[7]})", "not an object"},
        Hostile{"HugeChannel",
                R"({"op":"subscribe","subscriptions":[{"id":2,"channelId":18446744073709551615}]})",
                "integer"},
        Hostile{"DeepNesting", std::string(100000, '[') + std::string(100000, ']'), "nested deeper"},
        Hostile{"DeepInsideObject", R"({"op":"subscribe","x":)" + std::string(5000, '{') + "}",
                "nested deeper"},
        Hostile{"Utf8Garbage", "{\"op\":\"\xff\xfe\"}", ""},
        Hostile{"NulBytes", std::string("{\"op\":\0\"x\"}", 12), "not valid JSON"},
        Hostile{"TooLarge", std::string(kMaxClientFrame + 1, ' '), "limit"}),
    [](const ::testing::TestParamInfo<Hostile>& p) { return std::string(p.param.name); });

TEST(FoxgloveClient, BinaryFramesAreRefused) {
  ClientProtocol p(1);
  ClientProtocol::Outcome o;
  p.handle_binary(std::string("\x02\x01\x00\x00\x00\x01\x00\x00\x00\x00\x00\x00\x00", 13), o);
  const auto s = statuses(o);
  ASSERT_EQ(s.size(), 1u);
  EXPECT_EQ(s[0].first, 2);
  EXPECT_NE(s[0].second.find("binary"), std::string::npos);
}

TEST(FoxgloveClient, FrameAtTheLimitIsStillParsed) {
  std::string frame = R"({"op":"subscribe","subscriptions":[{"id":1,"channelId":1}]})";
  frame.resize(kMaxClientFrame, ' ');  // trailing whitespace is valid JSON
  ClientProtocol p(1);
  ClientProtocol::Outcome o;
  p.handle_text(frame, o);
  EXPECT_TRUE(o.replies.empty());
  EXPECT_EQ(p.subscription_count(), 1u);
}

// ---------------------------------------------------------------------------------------------
// Flow control

std::uint64_t frame_time(const ClientQueue::Frame& f) {
  std::uint64_t t = 0;
  if (f.data[0] == '\x01') std::memcpy(&t, f.data.data() + 5, 8);
  if (f.data[0] == '\x02') std::memcpy(&t, f.data.data() + 1, 8);
  return t;
}

std::vector<ClientQueue::Frame> drain(ClientQueue& q) {
  std::vector<ClientQueue::Frame> out;
  ClientQueue::Frame f;
  while (q.pop(f)) out.push_back(f);
  return out;
}

bool is_warning(const ClientQueue::Frame& f) {
  if (f.binary) return false;
  const Json j = parsed(f.data);
  return j.at("op") == "status" && j.at("level") == 1;
}

TEST(FoxgloveQueue, FifoWithinTheLimit) {
  ClientQueue q(QueueLimits{8, 1 << 20});
  q.push_text(R"({"op":"serverInfo"})");
  const auto payload = bytes("abc");
  for (std::uint64_t t = 1; t <= 5; ++t) q.push_message(ClientQueue::Kind::PerStep, 3, t, payload);
  q.push_time(6);
  EXPECT_EQ(q.size(), 7u);
  const auto frames = drain(q);
  ASSERT_EQ(frames.size(), 7u);
  EXPECT_FALSE(frames[0].binary);
  for (std::uint64_t t = 1; t <= 6; ++t) EXPECT_EQ(frame_time(frames[t]), t);
  EXPECT_EQ(frames[1].data.substr(13), "abc");
  EXPECT_EQ(frames[1].subscription, 3u);
  EXPECT_EQ(q.dropped(), 0u);
  EXPECT_EQ(q.bytes(), 0u);
}

TEST(FoxgloveQueue, FullQueueDropsTheOldestPerStepWithOneWarning) {
  ClientQueue q(QueueLimits{4, 1 << 20});
  q.push_text(R"({"op":"serverInfo"})");
  const auto payload = bytes("p");
  for (std::uint64_t t = 1; t <= 100; ++t) {
    q.push_message(ClientQueue::Kind::PerStep, 1, t, payload);
    EXPECT_LE(q.size(), 4u);
  }
  EXPECT_EQ(q.warnings(), 1u);
  const auto frames = drain(q);
  ASSERT_EQ(frames.size(), 4u);
  EXPECT_FALSE(frames[0].binary) << "the control frame stays first";
  std::vector<std::uint64_t> times;
  int warnings = 0;
  for (const auto& f : frames) {
    if (f.binary) times.push_back(frame_time(f));
    if (is_warning(f)) ++warnings;
  }
  EXPECT_EQ(warnings, 1);
  // The newest survive, in order.
  ASSERT_EQ(times.size(), 2u);
  EXPECT_EQ(times[0], 99u);
  EXPECT_EQ(times[1], 100u);
  EXPECT_EQ(q.dropped(), 98u);
}

TEST(FoxgloveQueue, LatchedAndControlFramesAreNeverDropped) {
  ClientQueue q(QueueLimits{3, 1 << 20});
  const auto payload = bytes("scene");
  q.push_message(ClientQueue::Kind::Latched, 1, 0, payload);
  q.push_message(ClientQueue::Kind::PerStep, 2, 1, payload);
  q.push_message(ClientQueue::Kind::Latched, 3, 2, payload);
  q.push_text(R"({"op":"serverInfo"})");  // over the limit: the per-step one goes
  q.push_message(ClientQueue::Kind::Latched, 4, 3, payload);
  for (std::uint64_t t = 10; t < 20; ++t) q.push_message(ClientQueue::Kind::PerStep, 2, t, payload);
  const auto frames = drain(q);
  std::vector<SubscriptionId> latched;
  int controls = 0, per_step = 0;
  for (const auto& f : frames) {
    if (f.kind == ClientQueue::Kind::Latched) latched.push_back(f.subscription);
    if (f.kind == ClientQueue::Kind::Control) ++controls;
    if (f.kind == ClientQueue::Kind::PerStep) ++per_step;
  }
  EXPECT_EQ(latched, (std::vector<SubscriptionId>{1, 3, 4}));
  EXPECT_EQ(controls, 2);  // serverInfo + one warning
  EXPECT_EQ(per_step, 0);  // no room for any: every per-step message was dropped
  EXPECT_EQ(q.dropped(), 11u);
  EXPECT_EQ(q.warnings(), 1u);
}

TEST(FoxgloveQueue, ByteLimitBoundsTheQueue) {
  ClientQueue q(QueueLimits{1000, 10'000});
  const std::vector<std::byte> payload(1000);
  for (std::uint64_t t = 0; t < 100; ++t) {
    q.push_message(ClientQueue::Kind::PerStep, 1, t, payload);
    EXPECT_LE(q.bytes(), 10'000u);
  }
  EXPECT_GT(q.dropped(), 80u);
  EXPECT_EQ(q.warnings(), 1u);
}

TEST(FoxgloveQueue, OneWarningPerBurst) {
  ClientQueue q(QueueLimits{4, 1 << 20});
  const auto payload = bytes("p");
  for (int burst = 1; burst <= 3; ++burst) {
    for (std::uint64_t t = 0; t < 50; ++t) q.push_message(ClientQueue::Kind::PerStep, 1, t, payload);
    EXPECT_EQ(q.warnings(), static_cast<std::uint64_t>(burst));
    // Draining to half the limit ends the burst; refilling without overflow warns nothing.
    drain(q);
    for (std::uint64_t t = 0; t < 4; ++t) q.push_message(ClientQueue::Kind::PerStep, 1, t, payload);
    EXPECT_EQ(q.warnings(), static_cast<std::uint64_t>(burst));
    drain(q);
  }
}

TEST(FoxgloveQueue, NoNewWarningWhileTheClientStaysBehind) {
  ClientQueue q(QueueLimits{8, 1 << 20});
  const auto payload = bytes("p");
  ClientQueue::Frame f;
  for (std::uint64_t t = 0; t < 1000; ++t) {
    q.push_message(ClientQueue::Kind::PerStep, 1, t, payload);
    q.push_message(ClientQueue::Kind::PerStep, 1, t, payload);
    q.pop(f);  // reads half of what comes
  }
  EXPECT_EQ(q.warnings(), 1u);
  EXPECT_GT(q.dropped(), 900u);
}

TEST(FoxgloveQueue, UnsubscribeRemovesQueuedMessagesOfThatSubscription) {
  ClientQueue q(QueueLimits{100, 1 << 20});
  const auto payload = bytes("p");
  for (std::uint64_t t = 0; t < 5; ++t) {
    q.push_message(ClientQueue::Kind::PerStep, 1, t, payload);
    q.push_message(ClientQueue::Kind::PerStep, 2, t, payload);
    q.push_time(t);
  }
  q.push_message(ClientQueue::Kind::Latched, 1, 9, payload);
  q.remove_subscription(1);
  const auto frames = drain(q);
  EXPECT_EQ(frames.size(), 10u);
  for (const auto& f : frames) {
    if (f.data[0] == '\x01') {
      EXPECT_EQ(f.subscription, 2u);
    }
  }
}

TEST(FoxgloveQueue, SteadyStateReusesBuffers) {
  ClientQueue q(QueueLimits{16, 1 << 20});
  const std::vector<std::byte> payload(4096);
  ClientQueue::Frame f;
  std::set<const char*> storage;
  for (std::uint64_t t = 0; t < 2000; ++t) {
    q.push_message(ClientQueue::Kind::PerStep, 1, t, payload);
    q.push_message(ClientQueue::Kind::PerStep, 1, t, payload);
    ASSERT_TRUE(q.pop(f));
    storage.insert(f.data.data());
    ASSERT_TRUE(q.pop(f));
    storage.insert(f.data.data());
  }
  // A handful of buffers circulate; a fresh allocation per message would give thousands.
  EXPECT_LE(storage.size(), 8u);
}

TEST(FoxgloveQueue, ManyLatchedFramesGrowTheQueuePastItsLimit) {
  ClientQueue q(QueueLimits{2, 1 << 20});
  const auto payload = bytes("s");
  for (SubscriptionId s = 0; s < 500; ++s) q.push_message(ClientQueue::Kind::Latched, s, 0, payload);
  EXPECT_EQ(q.size(), 500u);
  const auto frames = drain(q);
  ASSERT_EQ(frames.size(), 500u);
  for (SubscriptionId s = 0; s < 500; ++s) EXPECT_EQ(frames[s].subscription, s);
  EXPECT_EQ(q.dropped(), 0u);
}

// ---------------------------------------------------------------------------------------------
// Addresses

TEST(FoxgloveAddress, ParsesPortAndAddress) {
  ServerOptions o;
  ASSERT_TRUE(parse_listen_address("8765", o));
  EXPECT_EQ(o.address, "127.0.0.1");
  EXPECT_EQ(o.port, 8765);
  ASSERT_TRUE(parse_listen_address("0.0.0.0:0", o));
  EXPECT_EQ(o.address, "0.0.0.0");
  EXPECT_EQ(o.port, 0);
  ASSERT_TRUE(parse_listen_address("[::1]:9000", o));
  EXPECT_EQ(o.address, "::1");
  EXPECT_EQ(o.port, 9000);
  ASSERT_TRUE(parse_listen_address("localhost:65535", o));
  EXPECT_EQ(o.address, "127.0.0.1");
  EXPECT_EQ(o.port, 65535);
  for (const char* bad : {"", ":", "abc", "65536", "-1", "1.2.3:80", "127.0.0.1:", "127.0.0.1:80x", "host:80",
                          "[::1]80", "[nope]:80", "999999", "127.0.0.1:8765:1"}) {
    EXPECT_FALSE(parse_listen_address(bad, o)) << bad;
  }
}

TEST(FoxgloveAddress, LinkEncodesTheUrl) {
  EXPECT_EQ(websocket_url("127.0.0.1", 8765), "ws://127.0.0.1:8765");
  EXPECT_EQ(websocket_url("::1", 8765), "ws://[::1]:8765");
  EXPECT_EQ(foxglove_app_link("ws://127.0.0.1:8765"),
            "https://app.foxglove.dev/?ds=foxglove-websocket&ds.url=ws%3A%2F%2F127.0.0.1%3A8765");
}

}  // namespace
}  // namespace rbsim::foxglove
