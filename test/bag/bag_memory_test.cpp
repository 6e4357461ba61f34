// The recorder and the replay (rosbag2_transport's jobs, node/bag) over the in-memory middleware
// (rbsim/memory_middleware.hpp): no network, one process, so each test sees exactly what went
// through the seam. The end-to-end tests (test/e2e) run the same classes as separate processes over
// DDS; these pin down what the classes do with what they receive.
#include <gtest/gtest.h>

#include <algorithm>
#include <future>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "control_test_util.hpp"
#include "rbsim/control.hpp"
#include "rbsim/dds_sink.hpp"
#include "rbsim/interfaces.hpp"
#include "rbsim/mcap_sink.hpp"
#include "rbsim/memory_middleware.hpp"
#include "rbsim/node_services.hpp"
#include "rbsim/offline_run.hpp"
#include "rbsim/player.hpp"
#include "rbsim/recorder.hpp"
#include "rbsim/recording.hpp"
#include "rbsim/service.hpp"
#include "rbsim/service_event.hpp"
#include "rbsim/subprocess.hpp"

namespace rbsim::bag {

using namespace node;
namespace {

constexpr std::int64_t kSteps = 40;

Participant participant(const std::shared_ptr<MemoryNetwork>& network, const std::string& name) {
  Result<Participant> p = create_memory_participant(network, NodeName{"/", name});
  if (!p) throw std::runtime_error(p.error().message);
  return std::move(p.value());
}

// Every message of a recording, per topic in log-time order: the CDR payloads.
using Payloads = std::map<std::string, std::vector<Bytes>>;
Payloads payloads_of(const std::string& path, std::vector<std::string>* order = nullptr) {
  Result<std::unique_ptr<recordings::Recording>> r =
      recordings::Recording::open(path, recordings::raw_options());
  if (!r) throw std::runtime_error(r.error().message);
  Payloads out;
  const Status st = r.value()->read_messages({}, [&](const recordings::RecordedMessage& m) {
    out[m.topic()].emplace_back(m.cdr().begin(), m.cdr().end());
    if (order != nullptr) order->push_back(m.topic());
    return true;
  });
  if (!st) throw std::runtime_error(st.error().message);
  return out;
}

// `rbsim run --record`'s file of the control scene: what a node publishes, step for step.
std::string record_offline(const test::TempDir& dir, const Scene& scene) {
  const std::string path = (dir / "offline.mcap").string();
  std::unique_ptr<recordings::McapSink> sink = recordings::make_mcap_sink(path);
  Result<Driver> driver = Driver::create(scene);
  EXPECT_TRUE(driver.ok());
  driver.value().add(*sink);
  DriverOptions o;
  o.steps = kSteps;
  EXPECT_TRUE(driver.value().run_pass(o).ok());
  return path;
}

// A node's run over the memory network: DdsSink publishing every step (not finished: its flush
// would wait for readers that the calling thread drains afterwards).
struct MemoryNode {
  Participant participant;
  std::unique_ptr<DdsSink> sink;
  std::optional<Driver> driver;
  MemoryNode(const std::shared_ptr<MemoryNetwork>& network, const Scene& scene)
      : participant(bag::participant(network, "rbsim")) {
    Result<std::unique_ptr<DdsSink>> s = DdsSink::create(participant, NodeOptions{});
    if (!s) throw std::runtime_error(s.error().message);
    sink = std::move(s.value());
    Result<Driver> d = Driver::create(scene);
    if (!d) throw std::runtime_error(d.error().message);
    driver.emplace(std::move(d.value()));
    driver->add(*sink);
  }
  void run() {
    ASSERT_TRUE(driver->begin().ok());
    DriverOptions o;
    o.steps = kSteps;
    Result<PassEnd> end = driver->run(o);
    ASSERT_TRUE(end.ok());
    EXPECT_EQ(end.value(), PassEnd::Done);
  }
};

// Polls until `recorder` received `count` samples (bounded: the memory network delivers at
// publish time, so every poll finds what is there).
void drain(Recorder& recorder, std::uint64_t count) {
  for (int i = 0; i < 1000 && recorder.received() < count; ++i) ASSERT_TRUE(recorder.poll(1'000'000).ok());
  ASSERT_EQ(recorder.received(), count);
}

std::uint64_t total(const Payloads& p) {
  std::uint64_t n = 0;
  for (const auto& [topic, messages] : p) n += messages.size();
  return n;
}

TEST(Recorder, RecordsANodesRunAsRunRecordWritesIt) {
  test::TempDir dir;
  const Scene scene = test::control_scene();
  const Payloads offline = payloads_of(record_offline(dir, scene));
  auto network = std::make_shared<MemoryNetwork>();
  Participant rec = participant(network, "rbsim_recorder");
  RecorderOptions options;
  options.path = (dir / "live.mcap").string();
  Result<std::unique_ptr<Recorder>> recorder = Recorder::create(rec, options);
  ASSERT_TRUE(recorder.ok()) << recorder.error().message;
  MemoryNode node(network, scene);
  node.run();
  drain(*recorder.value(), total(offline));
  ASSERT_TRUE(recorder.value()->close().ok());

  std::vector<std::string> order;
  const Payloads live = payloads_of(options.path, &order);
  EXPECT_EQ(live, offline) << "the node's messages are run --record's, byte for byte, none lost or repeated";
  ASSERT_GE(order.size(), 2u);
  EXPECT_EQ(order[0], "/rbsim/scene");
  EXPECT_EQ(order[1], "/rbsim/markers");
  for (const Recorder::TopicCount& c : recorder.value()->counts()) {
    EXPECT_EQ(c.lost, 0u) << c.topic;
    EXPECT_EQ(c.duplicates, 0u) << c.topic;
  }
}

// A session whose bodies change (a spawn, a delete, SCOPE_SPAWNED), as a node publishes it and the
// recorder records it, re-simulated offline from its recorded commands into `run --record`'s file:
// every topic's payloads the same, byte for byte (each change a scene description, markers and
// its step again), and the recording reads back epoch by epoch.
TEST(Recorder, RecordsASessionWhoseBodiesChangeAsItsRerunWritesIt) {
  test::TempDir dir;
  const Scene scene = test::control_scene();
  auto network = std::make_shared<MemoryNetwork>();
  Participant rec = participant(network, "rbsim_recorder");
  RecorderOptions options;
  options.path = (dir / "live.mcap").string();
  Result<std::unique_ptr<Recorder>> recorder = Recorder::create(rec, options);
  ASSERT_TRUE(recorder.ok()) << recorder.error().message;
  {
    MemoryNode node(network, scene);
    control::Controller controller(scene, kSteps, control::RunSettings{0.0, 1, false});
    Result<std::unique_ptr<NodeServices>> services =
        NodeServices::create(node.participant, controller, NodeServicesOptions{"/rbsim"});
    ASSERT_TRUE(services.ok()) << services.error().message;
    controller.on_command(
        [&applied = *services.value()](const control::Command& c, const control::CommandResult& r) {
          applied.command_applied(c, r);
        });
    std::vector<std::future<control::CommandResult>> results;
    results.push_back(controller.submit(test::spawn_command(10, "triangle", {1.5, 6.0}, 0.0)));
    results.push_back(controller.submit(test::delete_command(20, "body_0")));
    control::Command reset;
    reset.step = 30;
    reset.kind = control::CommandKind::ResetSpawned;
    results.push_back(controller.submit(reset));
    ASSERT_TRUE(node.driver->begin().ok());
    DriverOptions o;
    o.steps = kSteps;
    o.control = &controller;
    Result<PassEnd> end = node.driver->run(o);
    ASSERT_TRUE(end.ok()) << end.error().message;
    for (auto& r : results) ASSERT_TRUE(r.get().successful);
  }
  // The memory network delivered every sample as it was published: take them all.
  for (int i = 0; i < 1000; ++i) {
    Result<bool> any = recorder.value()->poll(1'000'000);
    ASSERT_TRUE(any.ok()) << any.error().message;
    if (!any.value()) break;
  }
  ASSERT_TRUE(recorder.value()->close().ok());

  control::OfflineRunDef def;
  def.steps = kSteps;
  def.commands = options.path;
  def.record = {(dir / "rerun.mcap").string(), "--record"};
  Result<std::unique_ptr<control::OfflineRun>> rerun = control::OfflineRun::prepare(def, scene);
  ASSERT_TRUE(rerun.ok()) << rerun.error().message;
  Result<PassEnd> end = rerun.value()->run({});
  ASSERT_TRUE(end.ok()) << end.error().message;
  ASSERT_TRUE(rerun.value()->finish().ok());
  ASSERT_TRUE(rerun.value()->finish_commands().ok());

  const Payloads live = payloads_of(options.path), offline = payloads_of(def.record.path);
  EXPECT_EQ(live, offline);
  ASSERT_EQ(live.at("/rbsim/scene").size(), 4u) << "step 0 and one per change";
  ASSERT_EQ(live.at("/rbsim/commands").size(), 3u);
  // Read back: each step once, in its epoch (3 bodies from step 10, 2 from 20, 1 from 30).
  Result<std::unique_ptr<recordings::Recording>> r = recordings::Recording::open(options.path);
  ASSERT_TRUE(r.ok()) << r.error().message;
  std::vector<std::size_t> bodies;
  const Status st = r.value()->read_steps([&](const recordings::RecordedStep& s) -> Status {
    EXPECT_EQ(s.step, bodies.size());
    EXPECT_EQ(s.epoch, s.step < 10 ? 0u : s.step < 20 ? 1u : s.step < 30 ? 2u : 3u) << s.step;
    EXPECT_EQ(s.scene->bodies.size(), s.body_states->bodies.size());
    bodies.push_back(s.body_states->bodies.size());
    return Ok{};
  });
  ASSERT_TRUE(st.ok()) << st.error().message;
  ASSERT_EQ(bodies.size(), static_cast<std::size_t>(kSteps + 1));
  EXPECT_EQ(bodies[9], 2u);
  EXPECT_EQ(bodies[10], 3u);
  EXPECT_EQ(bodies[20], 2u);
  EXPECT_EQ(bodies[30], 1u);
}

// Publishers of the scene description, the markers and body states, as a node makes them, and the
// encoder of their messages: a test publishes in any order it likes.
struct HandNode {
  const Scene scene = test::control_scene();
  World world = World::create(scene.world).value();
  msgs::Encoder encoder{scene};
  Participant participant;
  Publisher scene_pub, markers_pub, body_pub;
  Bytes cdr;
  explicit HandNode(const std::shared_ptr<MemoryNetwork>& network)
      : participant(bag::participant(network, "rbsim")),
        scene_pub(make(msgs::TopicId::SceneDescription)),
        markers_pub(make(msgs::TopicId::Markers)),
        body_pub(make(msgs::TopicId::BodyStates)) {}
  Publisher make(msgs::TopicId id) {
    const msgs::TopicSpec& spec = msgs::topic(id);
    Result<Publisher> p =
        Publisher::create(participant, spec, msgs::topic_name(spec, "rbsim"), qos_for(spec));
    if (!p) throw std::runtime_error(p.error().message);
    return std::move(p.value());
  }
  void publish_latched() {
    encoder.scene(world, cdr);
    ASSERT_TRUE(scene_pub.publish(cdr).ok());
    encoder.markers(world, cdr);
    ASSERT_TRUE(markers_pub.publish(cdr).ok());
  }
  // Steps the world to `step` and publishes its body states.
  void publish_step(std::int64_t step) {
    while (world.step_index() < step) world.step();
    encoder.body_states(world, cdr);
    ASSERT_TRUE(body_pub.publish(cdr).ok());
  }
};

TEST(Recorder, HoldsPerStepSamplesUntilTheLatchedTopicsCame) {
  test::TempDir dir;
  auto network = std::make_shared<MemoryNetwork>();
  Participant rec = participant(network, "rbsim_recorder");
  RecorderOptions options;
  options.path = (dir / "held.mcap").string();
  Result<std::unique_ptr<Recorder>> recorder = Recorder::create(rec, options);
  ASSERT_TRUE(recorder.ok()) << recorder.error().message;
  HandNode node(network);
  node.publish_step(1);
  node.publish_step(2);
  drain(*recorder.value(), 2);  // taken and held: nothing written before the scene description
  node.publish_latched();
  node.publish_step(3);
  drain(*recorder.value(), 5);
  ASSERT_TRUE(recorder.value()->close().ok());
  std::vector<std::string> order;
  (void)payloads_of(options.path, &order);
  EXPECT_EQ(order, (std::vector<std::string>{"/rbsim/scene", "/rbsim/markers", "/rbsim/body_states",
                                             "/rbsim/body_states", "/rbsim/body_states"}));
}

TEST(Recorder, CountsTheStepsMissingFromATopicsSequenceAsLost) {
  test::TempDir dir;
  auto network = std::make_shared<MemoryNetwork>();
  Participant rec = participant(network, "rbsim_recorder");
  RecorderOptions options;
  options.path = (dir / "gaps.mcap").string();
  Result<std::unique_ptr<Recorder>> recorder = Recorder::create(rec, options);
  ASSERT_TRUE(recorder.ok()) << recorder.error().message;
  HandNode node(network);
  node.publish_latched();
  for (const std::int64_t step : {1, 2, 4, 5, 8}) node.publish_step(step);  // 3, 6 and 7 never sent
  drain(*recorder.value(), 7);
  ASSERT_TRUE(recorder.value()->close().ok());
  bool found = false;
  for (const Recorder::TopicCount& c : recorder.value()->counts()) {
    if (c.topic != "/rbsim/body_states") continue;
    found = true;
    EXPECT_EQ(c.received, 5u);
    EXPECT_EQ(c.lost, 3u);
  }
  EXPECT_TRUE(found);
}

// rbsim record --services: a node's service events (introspection on, contents) recorded like any
// topic, under their _Event type and its schema, each decoding to the call that was made.
TEST(Recorder, RecordsTheNodesServiceEvents) {
  test::TempDir dir;
  const Scene scene = test::control_scene();
  auto network = std::make_shared<MemoryNetwork>();
  Participant rec = participant(network, "rbsim_recorder");
  Participant node_side = participant(network, "rbsim");
  Participant client_side = participant(network, "client");
  const std::string service(msgs::GetParametersRequest::kService);
  RecorderOptions options;
  options.path = (dir / "events.mcap").string();
  options.topics = {"commands"};  // an event topic, so nothing waits for a scene description
  options.raw_topics = {{"/rbsim/get_parameters/_service_event", msgs::service_event_type(service)}};
  Result<std::unique_ptr<Recorder>> recorder = Recorder::create(rec, options);
  ASSERT_TRUE(recorder.ok()) << recorder.error().message;

  control::Controller controller(scene, kSteps, control::RunSettings{});
  NodeServicesOptions so{"/rbsim"};
  so.introspection = IntrospectionState::Contents;
  Result<std::unique_ptr<NodeServices>> services = NodeServices::create(node_side, controller, so);
  ASSERT_TRUE(services.ok()) << services.error().message;
  // The catalogue names the service as the node serves it.
  const std::vector<NodeServices::Served> served = NodeServices::catalogue();
  EXPECT_NE(std::find_if(served.begin(), served.end(),
                         [&](const auto& s) { return s.name == "get_parameters" && s.type == service; }),
            served.end());

  auto client = ServiceClient::create(client_side, "/rbsim/get_parameters", service);
  ASSERT_TRUE(client.ok());
  ASSERT_TRUE(client->wait_for_server(10.0).ok());
  msgs::GetParametersRequest req;
  req.names = {"rate", "dt"};
  Bytes req_cdr;
  msgs::encode(req, req_cdr);
  Result<Bytes> reply = client->call(req_cdr, 10.0);
  ASSERT_TRUE(reply.ok()) << reply.error().message;
  drain(*recorder.value(), 2);
  ASSERT_TRUE(recorder.value()->close().ok());

  Result<std::unique_ptr<recordings::Recording>> r =
      recordings::Recording::open(options.path, recordings::raw_options());
  ASSERT_TRUE(r.ok());
  bool found = false;
  for (const recordings::RecordedChannel& c : r.value()->channels()) {
    if (c.channel->topic != "/rbsim/get_parameters/_service_event") continue;
    found = true;
    ASSERT_NE(c.schema, nullptr);
    EXPECT_EQ(c.schema->name, "rcl_interfaces/srv/GetParameters_Event");
    EXPECT_EQ(c.schema_text(), msgs::ros2msg_schema(c.schema->name).value());
  }
  EXPECT_TRUE(found);
  const Payloads got = payloads_of(options.path);
  const auto events = got.find("/rbsim/get_parameters/_service_event");
  ASSERT_NE(events, got.end());
  ASSERT_EQ(events->second.size(), 2u);
  Result<msgs::ServiceEventCodec> codec = msgs::ServiceEventCodec::create(service);
  ASSERT_TRUE(codec.ok());
  msgs::ServiceEventInfo info;
  Bytes request, response;
  ASSERT_TRUE(codec.value().decode(events->second[0], info, request, response).ok());
  EXPECT_EQ(info.event_type, msgs::ServiceEventType::RequestReceived);
  EXPECT_EQ(request, req_cdr);
  ASSERT_TRUE(codec.value().decode(events->second[1], info, request, response).ok());
  EXPECT_EQ(info.event_type, msgs::ServiceEventType::ResponseSent);
  EXPECT_EQ(response, reply.value());
  EXPECT_EQ(services.value()->counters().service_events, 2u);
}

TEST(Recorder, TakesButDoesNotRecordWhilePaused) {
  test::TempDir dir;
  auto network = std::make_shared<MemoryNetwork>();
  Participant rec = participant(network, "rbsim_recorder");
  RecorderOptions options;
  options.path = (dir / "paused.mcap").string();
  Result<std::unique_ptr<Recorder>> recorder = Recorder::create(rec, options);
  ASSERT_TRUE(recorder.ok()) << recorder.error().message;
  HandNode node(network);
  node.publish_latched();
  node.publish_step(1);
  drain(*recorder.value(), 3);
  recorder.value()->set_paused(true);
  node.publish_step(2);
  node.publish_step(3);
  for (int i = 0; i < 1000 && recorder.value()->skipped_paused() < 2; ++i)
    ASSERT_TRUE(recorder.value()->poll(1'000'000).ok());
  EXPECT_EQ(recorder.value()->skipped_paused(), 2u);
  recorder.value()->set_paused(false);
  node.publish_step(4);
  for (int i = 0; i < 1000 && recorder.value()->received() < 4; ++i)
    ASSERT_TRUE(recorder.value()->poll(1'000'000).ok());
  ASSERT_TRUE(recorder.value()->close().ok());
  const Payloads p = payloads_of(options.path);
  ASSERT_EQ(p.count("/rbsim/body_states"), 1u);
  EXPECT_EQ(p.at("/rbsim/body_states").size(), 2u) << "steps 1 and 4 only";
}

// Every sample a subscription holds, in order.
std::vector<Bytes> take_all(Subscription& s) {
  std::vector<Bytes> out;
  Received r;
  for (int i = 0; i < 100000 && s.take(r); ++i) out.emplace_back(r.cdr.begin(), r.cdr.end());
  return out;
}

TEST(Player, RepublishesEveryRecordedMessageByteForByte) {
  test::TempDir dir;
  const Scene scene = test::control_scene();
  const std::string path = record_offline(dir, scene);
  const Payloads recorded = payloads_of(path);
  auto network = std::make_shared<MemoryNetwork>();
  Participant viewer = participant(network, "viewer");
  // Per-step readers before the replay starts (their messages are volatile); the latched ones
  // after it played, to show a late joiner still gets the scene description and the markers.
  std::map<std::string, Subscription> subs;
  const auto subscribe = [&](const msgs::TopicSpec& spec) {
    const std::string name = msgs::topic_name(spec, "rbsim");
    Result<Subscription> s = Subscription::create(viewer, spec, name, qos_for(spec));
    ASSERT_TRUE(s.ok()) << s.error().message;
    subs.emplace(name, std::move(s.value()));
  };
  for (const msgs::TopicSpec& spec : msgs::topics())
    if (!spec.latched() && recorded.count(msgs::topic_name(spec, "rbsim")) != 0) subscribe(spec);
  ASSERT_FALSE(subs.empty());

  Participant player = participant(network, "rbsim_player");
  PlayOptions options;
  options.path = path;
  options.rate = 0.0;
  options.services = false;
  Result<std::unique_ptr<Player>> replay = Player::open(player, options);
  ASSERT_TRUE(replay.ok()) << replay.error().message;
  Result<bool> played = replay.value()->play(+[] { return false; });
  ASSERT_TRUE(played.ok()) << played.error().message;
  EXPECT_TRUE(played.value());
  for (const msgs::TopicSpec& spec : msgs::topics())
    if (spec.latched() && recorded.count(msgs::topic_name(spec, "rbsim")) != 0) subscribe(spec);

  Payloads received;
  for (auto& [name, sub] : subs) received[name] = take_all(sub);
  EXPECT_EQ(received, recorded);
  EXPECT_EQ(replay.value()->published(), total(recorded));
}

// rbsim replay --foxglove's tap: a pass starts a session with the simulated time playing starts at
// (--start-offset's step), before any message, latched ones included (stamped where the scene
// began), so a viewer joining the paused replay learns where it stands; per-step messages then
// start at that time.
TEST(Player, TheTapStartsASessionWithTheTimePlayingStartsAt) {
  test::TempDir dir;
  const std::string path = record_offline(dir, test::control_scene());  // dt 0.01 s
  for (const auto& [offset, start] : {std::pair{0.0, 0ull}, std::pair{0.1, 100'000'000ull}}) {
    auto network = std::make_shared<MemoryNetwork>();
    Participant player = participant(network, "rbsim_player");
    PlayOptions options;
    options.path = path;
    options.rate = 0.0;
    options.services = false;
    options.start_offset = offset;
    Result<std::unique_ptr<Player>> replay = Player::open(player, options);
    ASSERT_TRUE(replay.ok()) << replay.error().message;
    std::vector<std::optional<std::uint64_t>> passes;
    std::vector<std::pair<bool, std::uint64_t>> messages;  // latched, simulated time
    Player::Tap tap;
    tap.pass = [&](std::optional<std::uint64_t> at) {
      EXPECT_TRUE(messages.empty()) << "a session starts before its messages";
      passes.push_back(at);
    };
    tap.message = [&](std::size_t output, std::uint64_t t, std::span<const std::byte>) {
      messages.emplace_back(replay.value()->outputs().at(output).latched, t);
    };
    Result<bool> played = replay.value()->play(
        +[] { return false; }, &tap);
    ASSERT_TRUE(played.ok()) << played.error().message;
    ASSERT_EQ(passes.size(), 1u) << offset;
    EXPECT_EQ(passes[0], std::optional(start)) << offset;
    ASSERT_GT(messages.size(), 2u);
    EXPECT_TRUE(messages[0].first && messages[1].first) << "the scene description and markers first";
    EXPECT_EQ(messages[0].second, 0u);
    EXPECT_FALSE(messages[2].first);
    EXPECT_EQ(messages[2].second, start) << offset;
  }
}

TEST(Player, ServesThePlayersServicesOnTheNetwork) {
  test::TempDir dir;
  const std::string path = record_offline(dir, test::control_scene());
  auto network = std::make_shared<MemoryNetwork>();
  Participant player = participant(network, "rbsim_player");
  PlayOptions options;
  options.path = path;
  options.rate = 0.0;
  options.start_paused = true;
  Result<std::unique_ptr<Player>> replay = Player::open(player, options);
  ASSERT_TRUE(replay.ok()) << replay.error().message;

  Participant client_node = participant(network, "client");
  const auto client = [&](const std::string& name, std::string_view type) {
    Result<ServiceClient> c = ServiceClient::create(client_node, "/rbsim_player/" + name, type);
    if (!c) throw std::runtime_error(c.error().message);
    return std::move(c.value());
  };
  ServiceClient is_paused = client("is_paused", msgs::IsPausedRequest::kService);
  ServiceClient set_rate = client("set_rate", msgs::SetRateRequest::kService);
  ASSERT_TRUE(is_paused.wait_for_server(10.0).ok());
  Bytes request, reply;
  msgs::encode(msgs::IsPausedRequest{}, request);
  Result<Bytes> paused = is_paused.call(request, 10.0);
  ASSERT_TRUE(paused.ok()) << paused.error().message;
  msgs::IsPausedResponse pr;
  ASSERT_TRUE(msgs::decode(paused.value(), pr).ok());
  EXPECT_TRUE(pr.paused);

  msgs::encode(msgs::SetRateRequest{2.5}, request);
  ASSERT_TRUE(set_rate.wait_for_server(10.0).ok());
  Result<Bytes> set = set_rate.call(request, 10.0);
  ASSERT_TRUE(set.ok()) << set.error().message;
  msgs::SetRateResponse sr;
  ASSERT_TRUE(msgs::decode(set.value(), sr).ok());
  EXPECT_TRUE(sr.success);
  EXPECT_EQ(replay.value()->status().rate, 2.5);
  EXPECT_TRUE(replay.value()->status().paused);
}

}  // namespace
}  // namespace rbsim::bag
