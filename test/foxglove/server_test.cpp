// The Foxglove server over real sockets on 127.0.0.1 (port 0: a free port), with the minimal
// client of ws_client.hpp: handshake and subprotocols, serverInfo/advertise, latched delivery to
// new subscriptions, the last time to a new client, per-step data, sessions, hostile input, a stalled client
// (the producer is not slowed, others lose nothing, the staller is disconnected), the sink,
// connect/disconnect churn. Every wait is bounded in count and time.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <chrono>
#include <cstring>
#include <thread>

#include "rbsim/foxglove.hpp"
#include "rbsim/run.hpp"
#include "ws_client.hpp"

namespace rbsim::foxglove {
namespace {

using Json = nlohmann::json;
using test::WsClient;
using Clock = std::chrono::steady_clock;

std::vector<ChannelSpec> two_channels() {
  std::vector<ChannelSpec> c(2);
  c[0].topic = "/t/scene";
  c[0].schema_name = "rbsim_msgs/msg/SceneDescription";
  c[0].schema = "string name\n";
  c[0].latched = true;
  c[1].topic = "/t/states";
  c[1].schema_name = "rbsim_msgs/msg/BodyStates";
  c[1].schema = "uint64 step\n";
  return c;
}

std::unique_ptr<Server> start(ServerOptions o = {}, std::vector<ChannelSpec> channels = two_channels()) {
  o.address = "127.0.0.1";
  o.port = 0;
  auto s = Server::start(o, std::move(channels));
  EXPECT_TRUE(s) << (s ? "" : s.error().message);
  return s ? std::move(s.value()) : nullptr;
}

std::vector<std::byte> bytes(std::string_view s) {
  std::vector<std::byte> b(s.size());
  std::memcpy(b.data(), s.data(), s.size());
  return b;
}

Json next_json(WsClient& c) {
  auto f = c.read();
  if (!f) return Json();
  EXPECT_EQ(f->opcode, 1) << "expected a text frame";
  return Json::parse(f->data, nullptr, false);
}

struct Data {
  std::uint32_t subscription = 0;
  std::uint64_t log_time = 0;
  std::string payload;
};
std::optional<Data> as_data(const WsClient::Frame& f) {
  if (f.opcode != 2 || f.data.size() < 13 || f.data[0] != '\x01') return std::nullopt;
  Data d;
  std::memcpy(&d.subscription, f.data.data() + 1, 4);
  std::memcpy(&d.log_time, f.data.data() + 5, 8);
  d.payload = f.data.substr(13);
  return d;
}

// Connects, checks serverInfo and advertise, and returns the session id.
std::string handshake(WsClient& c, std::uint16_t port,
                      const std::string& protocol = "foxglove.websocket.v1") {
  EXPECT_EQ(c.connect(port, {protocol}), 101) << c.response();
  EXPECT_EQ(c.protocol(), protocol);
  const Json info = next_json(c);
  EXPECT_EQ(info.value("op", ""), "serverInfo") << info;
  const Json adv = next_json(c);
  EXPECT_EQ(adv.value("op", ""), "advertise") << adv;
  return info.value("sessionId", "");
}

// Waits (bounded) until `pred` holds.
template <class P>
bool eventually(P pred, std::chrono::milliseconds limit = std::chrono::milliseconds(5000)) {
  const auto end = Clock::now() + limit;
  while (Clock::now() < end) {
    if (pred()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return pred();
}

// Sends `subscribe` and returns once the server has taken it in: it handles a client's frames in
// order, so its answer to a frame sent after (an unsubscribe of an id never given: a status) says
// the subscription is in place. Reads at most 16 frames (serverInfo and advertise included), each
// within the client's 5 s timeout.
::testing::AssertionResult subscribed(WsClient& c, const std::string& subscribe) {
  if (!c.send_text(subscribe) || !c.send_text(R"({"op":"unsubscribe","subscriptionIds":[987654321]})"))
    return ::testing::AssertionFailure() << "cannot send";
  for (int i = 0; i < 16; ++i) {
    auto f = c.read();
    if (!f) return ::testing::AssertionFailure() << "no status reply to the probe after " << subscribe;
    if (f->opcode != 1) continue;
    const Json j = Json::parse(f->data, nullptr, false);
    if (j.is_object() && j.value("op", "") == "status") return ::testing::AssertionSuccess();
  }
  return ::testing::AssertionFailure() << "16 frames without the probe's status reply";
}

// The next frame, a time message: its time (nullopt: another frame or none).
std::optional<std::uint64_t> time_of(WsClient& c) {
  auto f = c.read();
  if (!f || f->opcode != 2 || f->data.size() != 9 || f->data[0] != '\x02') return std::nullopt;
  std::uint64_t t = 0;
  std::memcpy(&t, f->data.data() + 1, 8);
  return t;
}

TEST(FoxgloveServer, AnswersEitherSubprotocolWithServerInfoAndAdvertise) {
  auto server = start();
  ASSERT_TRUE(server);
  ASSERT_GT(server->port(), 0);
  for (const std::string p : {"foxglove.sdk.v1", "foxglove.websocket.v1"}) {
    WsClient c;
    ASSERT_EQ(c.connect(server->port(), {"chat", p}), 101) << c.response();
    EXPECT_EQ(c.protocol(), p);
    const Json info = next_json(c);
    EXPECT_EQ(info["op"], "serverInfo");
    EXPECT_EQ(info["capabilities"], Json::array({"time"}));
    EXPECT_FALSE(info["sessionId"].get<std::string>().empty());
    const Json adv = next_json(c);
    ASSERT_EQ(adv["op"], "advertise");
    ASSERT_EQ(adv["channels"].size(), 2u);
    EXPECT_EQ(adv["channels"][0]["topic"], "/t/scene");
    EXPECT_EQ(adv["channels"][1]["schemaName"], "rbsim_msgs/msg/BodyStates");
  }
  EXPECT_EQ(server->stats().clients, 2u);
}

TEST(FoxgloveServer, RefusesOtherSubprotocolsInTheHandshake) {
  auto server = start();
  ASSERT_TRUE(server);
  for (const std::vector<std::string>& offered :
       {std::vector<std::string>{}, {"chat"}, {"foxglove.websocket.v2"}}) {
    WsClient c;
    const int status = c.connect(server->port(), offered);
    EXPECT_NE(status, 101) << c.response();
  }
  EXPECT_TRUE(eventually([&] { return server->stats().refused == 3; }));
  EXPECT_EQ(server->stats().clients, 0u);
}

TEST(FoxgloveServer, LatchedGoesToEveryNewSubscriptionAndPerStepToSubscribers) {
  auto server = start();
  ASSERT_TRUE(server);
  EXPECT_FALSE(server->subscribed(2));
  server->publish(1, 5, bytes("scene-1"));  // before anyone subscribes: kept
  server->publish(2, 6, bytes("nobody"));   // nobody subscribes: gone
  WsClient c;
  handshake(c, server->port());
  ASSERT_TRUE(
      c.send_text(R"({"op":"subscribe","subscriptions":[{"id":10,"channelId":1},{"id":11,"channelId":2}]})"));
  auto f = c.read();
  ASSERT_TRUE(f);
  auto d = as_data(*f);
  ASSERT_TRUE(d);
  EXPECT_EQ(d->subscription, 10u);
  EXPECT_EQ(d->log_time, 5u);
  EXPECT_EQ(d->payload, "scene-1");
  ASSERT_TRUE(eventually([&] { return server->subscribed(2); }));
  for (std::uint64_t t = 100; t < 110; ++t) server->publish(2, t, bytes("step" + std::to_string(t)));
  server->time(110);
  for (std::uint64_t t = 100; t < 110; ++t) {
    f = c.read();
    ASSERT_TRUE(f);
    d = as_data(*f);
    ASSERT_TRUE(d);
    EXPECT_EQ(d->subscription, 11u);
    EXPECT_EQ(d->log_time, t);
    EXPECT_EQ(d->payload, "step" + std::to_string(t));
  }
  f = c.read();
  ASSERT_TRUE(f);
  ASSERT_EQ(f->data.size(), 9u);
  EXPECT_EQ(f->data[0], '\x02');
  std::uint64_t t = 0;
  std::memcpy(&t, f->data.data() + 1, 8);
  EXPECT_EQ(t, 110u);

  // A second client subscribing later gets the last time message, then the newest latched
  // message at once.
  server->publish(1, 7, bytes("scene-2"));
  WsClient late;
  handshake(late, server->port(), "foxglove.sdk.v1");
  ASSERT_TRUE(late.send_text(R"({"op":"subscribe","subscriptions":[{"id":1,"channelId":1}]})"));
  EXPECT_EQ(time_of(late), 110u);
  f = late.read();
  ASSERT_TRUE(f);
  d = as_data(*f);
  ASSERT_TRUE(d);
  EXPECT_EQ(d->payload, "scene-2");
  EXPECT_EQ(d->subscription, 1u);

  // Unsubscribed: no more data on that channel.
  ASSERT_TRUE(c.send_text(R"({"op":"unsubscribe","subscriptionIds":[11]})"));
  ASSERT_TRUE(eventually([&] { return !server->subscribed(2); }));
}

TEST(FoxgloveServer, NewSessionSendsANewServerInfoAndForgetsLatched) {
  auto server = start();
  ASSERT_TRUE(server);
  WsClient c;
  const std::string first = handshake(c, server->port());
  server->publish(1, 1, bytes("old scene"));
  server->new_session();
  const Json info = next_json(c);
  EXPECT_EQ(info["op"], "serverInfo");
  EXPECT_NE(info["sessionId"], first);
  // The old session's scene is not given to a subscription in the new one.
  ASSERT_TRUE(c.send_text(R"({"op":"subscribe","subscriptions":[{"id":1,"channelId":1}]})"));
  ASSERT_TRUE(eventually([&] { return server->subscribed(1); }));
  server->publish(1, 2, bytes("new scene"));
  auto f = c.read();
  ASSERT_TRUE(f);
  auto d = as_data(*f);
  ASSERT_TRUE(d);
  EXPECT_EQ(d->payload, "new scene");
}

// A client that connects gets the session's last time message right after the advertisements,
// before what it subscribes to: a viewer joining a paused stream (a paused replay sends nothing)
// learns where it stands before its latched messages. A new session has no time until one is sent.
TEST(FoxgloveServer, AClientThatConnectsGetsTheLastTimeBeforeItsLatchedMessages) {
  auto server = start();
  ASSERT_TRUE(server);
  server->time(42);
  server->publish(1, 5, bytes("scene"));
  server->time(77);
  WsClient c;
  handshake(c, server->port());
  ASSERT_TRUE(c.send_text(R"({"op":"subscribe","subscriptions":[{"id":3,"channelId":1}]})"));
  EXPECT_EQ(time_of(c), 77u);
  auto f = c.read();
  ASSERT_TRUE(f);
  auto d = as_data(*f);
  ASSERT_TRUE(d);
  EXPECT_EQ(d->payload, "scene");

  server->new_session();
  server->publish(1, 6, bytes("scene-2"));
  WsClient fresh;
  handshake(fresh, server->port());
  ASSERT_TRUE(fresh.send_text(R"({"op":"subscribe","subscriptions":[{"id":4,"channelId":1}]})"));
  f = fresh.read();
  ASSERT_TRUE(f);
  d = as_data(*f);
  ASSERT_TRUE(d) << "a new session's first frame is its latched message, no time of the old one";
  EXPECT_EQ(d->payload, "scene-2");
  server->time(80);
  EXPECT_EQ(time_of(fresh), 80u);
}

TEST(FoxgloveServer, HostileInputGetsAStatusAndTheConnectionKeepsWorking) {
  auto server = start();
  ASSERT_TRUE(server);
  WsClient c;
  handshake(c, server->port());
  for (const std::string& bad :
       {std::string("{not json"), std::string(R"({"op":"explode"})"), std::string("[]"),
        std::string(R"({"op":"subscribe","subscriptions":[{"id":1,"channelId":77}]})"),
        std::string(R"({"op":"unsubscribe","subscriptionIds":[5]})")}) {
    ASSERT_TRUE(c.send_text(bad));
    const Json s = next_json(c);
    EXPECT_EQ(s.value("op", ""), "status") << bad;
    EXPECT_EQ(s.value("level", -1), 2) << bad;
  }
  ASSERT_TRUE(c.send_binary(std::string("\x01\x01\x00\x00\x00xyz", 8)));
  const Json s = next_json(c);
  EXPECT_EQ(s.value("op", ""), "status");
  ASSERT_TRUE(c.send_text(R"({"op":"subscribe","subscriptions":[{"id":1,"channelId":2}]})"));
  ASSERT_TRUE(eventually([&] { return server->subscribed(2); }));
  server->publish(2, 3, bytes("ok"));
  auto f = c.read();
  ASSERT_TRUE(f);
  ASSERT_TRUE(as_data(*f));
  EXPECT_EQ(as_data(*f)->payload, "ok");
}

TEST(FoxgloveServer, AFrameOverTheLimitIsRefusedAndAHugeOneClosesTheConnection) {
  auto server = start();
  ASSERT_TRUE(server);
  WsClient c;
  handshake(c, server->port());
  // Over the 1 MiB limit: read whole and answered with a status error; the connection stays.
  (void)c.send_text(std::string(kMaxClientFrame + 10, ' '));
  bool refused = false;
  for (int i = 0; i < 10 && !refused; ++i) {
    auto f = c.read();
    ASSERT_TRUE(f) << "connection ended instead of a status error";
    refused = f->opcode == 1 && f->data.find("\"status\"") != std::string::npos &&
              f->data.find("limit") != std::string::npos;
  }
  EXPECT_TRUE(refused);
  // Over what the transport reads: a close frame (1009) or the end of the stream; never a hang.
  (void)c.send_text(std::string(kMaxReadFrame + 10, ' '));
  bool closed = false;
  for (int i = 0; i < 10 && !closed; ++i) {
    auto f = c.read();
    closed = !f || f->opcode == 8;
  }
  EXPECT_TRUE(closed);
  EXPECT_TRUE(eventually([&] { return server->client_count() == 0; }));
  // The server still serves.
  WsClient again;
  handshake(again, server->port());
}

TEST(FoxgloveServer, AStalledClientSlowsNeitherTheProducerNorOthersAndIsDisconnected) {
  ServerOptions o;
  o.queue = QueueLimits{64, 4u << 20};
  o.max_in_flight_bytes = 1u << 20;
  o.stall_timeout_s = 0.5;
  auto server = start(o);
  ASSERT_TRUE(server);
  WsClient stalled, good;
  // The staller subscribes and never reads again; its small window fills at once.
  // Both subscriptions in place before the first publish (the staller reads only up to the
  // answer to its probe).
  ASSERT_EQ(stalled.connect(server->port(), {"foxglove.websocket.v1"}, 4096), 101);
  ASSERT_TRUE(subscribed(stalled, R"({"op":"subscribe","subscriptions":[{"id":1,"channelId":2}]})"));
  handshake(good, server->port());
  ASSERT_TRUE(subscribed(good, R"({"op":"subscribe","subscriptions":[{"id":2,"channelId":2}]})"));
  ASSERT_EQ(server->client_count(), 2u);

  // The good client reads on its own thread, as fast as it can.
  constexpr int kMessages = 400;
  std::vector<std::uint64_t> received;
  std::thread reader([&] {
    while (static_cast<int>(received.size()) < kMessages) {
      auto f = good.read();
      if (!f) break;
      if (auto d = as_data(*f)) received.push_back(d->log_time);
    }
  });
  const std::vector<std::byte> payload(64 * 1024);
  const auto t0 = Clock::now();
  for (int i = 0; i < kMessages; ++i) {
    server->publish(2, static_cast<std::uint64_t>(i), payload);
    std::this_thread::sleep_for(std::chrono::microseconds(500));  // a producer at ~2 kHz
  }
  const double publish_s = std::chrono::duration<double>(Clock::now() - t0).count();
  reader.join();
  // 400 sleeps of 0.5 ms: publishing itself added little (it never waits for a socket).
  EXPECT_LT(publish_s, 2.0);
  ASSERT_EQ(received.size(), static_cast<std::size_t>(kMessages)) << "the reading client lost messages";
  for (int i = 0; i < kMessages; ++i) EXPECT_EQ(received[i], static_cast<std::uint64_t>(i));
  EXPECT_TRUE(eventually([&] { return server->stats().disconnected == 1; }));
  EXPECT_TRUE(eventually([&] { return server->client_count() == 1; }));
  EXPECT_GT(server->stats().dropped, 0u);
}

TEST(FoxgloveServer, FlushWaitsForAReaderButNotForeverForAStaller) {
  auto server = start();
  ASSERT_TRUE(server);
  WsClient reader;
  handshake(reader, server->port());
  ASSERT_TRUE(reader.send_text(R"({"op":"subscribe","subscriptions":[{"id":1,"channelId":2}]})"));
  ASSERT_TRUE(eventually([&] { return server->subscribed(2); }));
  const std::vector<std::byte> payload(64 * 1024);
  int got = 0;
  std::thread t([&] {
    while (got < 50) {
      auto f = reader.read();
      if (!f) break;
      if (as_data(*f)) ++got;
    }
  });
  for (int i = 0; i < 50; ++i) server->publish(2, static_cast<std::uint64_t>(i), payload);
  EXPECT_TRUE(server->flush(10.0));
  t.join();
  EXPECT_EQ(got, 50);

  // A client that reads nothing: flush gives up at its timeout.
  WsClient staller;
  ASSERT_EQ(staller.connect(server->port(), {"foxglove.sdk.v1"}, 4096), 101);
  ASSERT_TRUE(subscribed(staller, R"({"op":"subscribe","subscriptions":[{"id":1,"channelId":2}]})"));
  ASSERT_EQ(server->client_count(), 2u);
  for (int i = 0; i < 200; ++i) server->publish(2, static_cast<std::uint64_t>(i), payload);
  const auto t0 = Clock::now();
  EXPECT_FALSE(server->flush(0.3));
  EXPECT_LT(std::chrono::duration<double>(Clock::now() - t0).count(), 2.0);
}

TEST(FoxgloveServer, APortInUseIsAClearError) {
  auto first = start();
  ASSERT_TRUE(first);
  ServerOptions o;
  o.port = first->port();
  auto second = Server::start(o, two_channels());
  ASSERT_FALSE(second);
  EXPECT_NE(second.error().message.find("in use"), std::string::npos) << second.error().message;
  EXPECT_NE(second.error().message.find(std::to_string(first->port())), std::string::npos);
}

TEST(FoxgloveServer, HundredsOfConnectsAndDisconnects) {
  auto server = start();
  ASSERT_TRUE(server);
  for (int i = 0; i < 300; ++i) {
    WsClient c;
    ASSERT_EQ(c.connect(server->port(), {"foxglove.sdk.v1"}), 101) << i;
    if (i % 2 == 0) (void)c.send_text(R"({"op":"subscribe","subscriptions":[{"id":1,"channelId":2}]})");
    if (i % 3 == 0) server->publish(2, static_cast<std::uint64_t>(i), bytes("x"));
  }
  EXPECT_TRUE(eventually([&] { return server->client_count() == 0; }));
  EXPECT_FALSE(server->subscribed(2));
  WsClient c;
  handshake(c, server->port());
  EXPECT_EQ(server->stats().clients, 301u);
}

TEST(FoxgloveServer, StopClosesClientsPromptly) {
  auto server = start();
  ASSERT_TRUE(server);
  WsClient c, silent;
  handshake(c, server->port());
  ASSERT_EQ(silent.connect(server->port(), {"foxglove.sdk.v1"}), 101);
  const auto t0 = Clock::now();
  server->stop();
  EXPECT_LT(std::chrono::duration<double>(Clock::now() - t0).count(), 3.0);
  bool closed = false;
  for (int i = 0; i < 10 && !closed; ++i) {
    auto f = c.read();
    closed = !f || f->opcode == 8;
  }
  EXPECT_TRUE(closed);
}

// The sink: latched scene at begin, per-step topics that have a subscriber, log time = simulated
// time, payloads = the Encoder's bytes (what MCAP and DDS carry).
Scene two_body_scene() {
  Scene scene;
  scene.name = "two";
  scene.world.dt = 0.01;
  scene.world.integrator = Integrator::SymplecticEuler;
  for (int i = 0; i < 2; ++i) {
    BodyDef b;
    b.hull = {{0.0 + 2 * i, 0.0}, {0.0 + 2 * i, 1.0}, {1.0 + 2 * i, 0.0}};
    b.masses = {1.0, 1.0, 1.0};
    b.radius = 0.1;
    scene.world.bodies.push_back(b);
    scene.body_colors.push_back(Color{0.5, 0.25, 1.0});
  }
  scene.world.gravity.push_back(GravityDef{{0.0, -9.81}});
  scene.duration = 0.05;
  return scene;
}

TEST(FoxgloveSink, PublishesTheSceneLatchedAndSubscribedStepsAtSimulatedTime) {
  const Scene scene = two_body_scene();
  std::vector<ChannelId> ids;
  auto channels = ros2_channels(msgs::default_topics(), "rbsim", &ids);
  ASSERT_TRUE(channels);
  auto server = start({}, channels.value());
  ASSERT_TRUE(server);
  const ChannelId scene_ch = ids[static_cast<std::size_t>(msgs::TopicId::SceneDescription)];
  const ChannelId states_ch = ids[static_cast<std::size_t>(msgs::TopicId::BodyStates)];
  ASSERT_GT(scene_ch, 0u);
  ASSERT_GT(states_ch, 0u);

  WsClient c;
  handshake(c, server->port());
  ASSERT_TRUE(c.send_text(R"({"op":"subscribe","subscriptions":[{"id":3,"channelId":)" +
                          std::to_string(states_ch) + "}]}"));
  ASSERT_TRUE(eventually([&] { return server->subscribed(states_ch); }));

  SinkOptions so;
  so.publish_every = 2;
  FoxgloveSink sink(*server, ids, so);
  auto driver = Driver::create(scene);
  ASSERT_TRUE(driver);
  driver.value().add(sink);
  ASSERT_TRUE(driver.value().begin());
  DriverOptions d;
  d.steps = 5;
  auto end = driver.value().run(d);
  ASSERT_TRUE(end);
  ASSERT_TRUE(driver.value().finish());

  // serverInfo of the new session, then steps 0, 2, 4 (body states, then the step's time).
  EXPECT_EQ(next_json(c)["op"], "serverInfo");
  msgs::Encoder encoder(scene);
  for (std::int64_t step : {0, 2, 4}) {
    auto f = c.read();
    ASSERT_TRUE(f);
    auto data = as_data(*f);
    ASSERT_TRUE(data);
    EXPECT_EQ(data->subscription, 3u);
    const auto want_time = static_cast<std::uint64_t>(std::llround(static_cast<double>(step) * 0.01 * 1e9));
    EXPECT_EQ(data->log_time, want_time);
    auto t = c.read();
    ASSERT_TRUE(t);
    ASSERT_EQ(t->data.size(), 9u);
    ASSERT_EQ(t->data[0], '\x02') << "the step's time after its messages";
    std::uint64_t time_ns = 0;
    for (int i = 0; i < 8; ++i)
      time_ns |= static_cast<std::uint64_t>(static_cast<unsigned char>(t->data[1 + i])) << (8 * i);
    EXPECT_EQ(time_ns, want_time);
    msgs::BodyStatesMessage m;
    ASSERT_TRUE(msgs::decode_body_states(std::as_bytes(std::span(data->payload)), m));
    EXPECT_EQ(m.step, static_cast<std::uint64_t>(step));
    EXPECT_EQ(m.bodies.size(), 2u);
  }

  // A late subscriber to the scene gets the time of the last step, then the run's scene
  // description, byte for byte.
  WsClient late;
  handshake(late, server->port());
  ASSERT_TRUE(late.send_text(R"({"op":"subscribe","subscriptions":[{"id":9,"channelId":)" +
                             std::to_string(scene_ch) + "}]}"));
  EXPECT_EQ(time_of(late), 40'000'000u);
  auto f = late.read();
  ASSERT_TRUE(f);
  auto data = as_data(*f);
  ASSERT_TRUE(data);
  auto world = World::create(scene.world);
  ASSERT_TRUE(world);
  msgs::Bytes want;
  encoder.scene(world.value(), want);
  EXPECT_EQ(data->payload, std::string(reinterpret_cast<const char*>(want.data()), want.size()));
  EXPECT_EQ(data->log_time, 0u);
}

}  // namespace
}  // namespace rbsim::foxglove
