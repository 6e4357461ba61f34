// simulation_interfaces' services on the node (node/sim/src/simulation_services.*), called as a
// ROS 2 client calls them: a node of this process (a Controller and its NodeServices, the control
// tests' run loop on another thread), over the loopback DDS configuration and over the in-memory
// middleware. The states are checked against a World stepped here, the codes against the
// definitions' constants.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <sys/sysmacros.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <future>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "control_test_util.hpp"
#include "rbsim/cdr.hpp"
#include "rbsim/command_script.hpp"
#include "rbsim/dds.hpp"
#include "rbsim/dds_sink.hpp"
#include "rbsim/forwarded_service.hpp"
#include "rbsim/memory_middleware.hpp"
#include "rbsim/node_services.hpp"
#include "rbsim/service_event.hpp"
#include "rbsim/simulation_interfaces.hpp"
#include "sim_test_util.hpp"

namespace rbsim::node {
namespace {

using namespace std::chrono_literals;
namespace sim = msgs::simulation;
using SimResult = sim::Result;
using State = sim::State;
using SetRes = sim::SetSimulationStateResponse;

constexpr std::uint32_t kDomain = 159;    // its own: test/dds has 143..157, test/middleware 158
constexpr std::int64_t kSteps = 1000000;  // never reached: each test ends the run itself

// A node of this process: paused at step 0 (STOPPED), the run loop on another thread at real
// time, and a client participant.
class SimulationServicesTest : public ::testing::TestWithParam<std::string> {
 protected:
  void SetUp() override {
    node_ = test::node_name("sim_services");
    server_.emplace(participant(node_));
    NodeServicesOptions options;
    options.node = "/" + node_;
    // As rbsim node's STATE_QUITTING asks its loop to stop: here the controller ends the run.
    options.quit = [this] {
      ++quits_;
      controller_.close("quitting");
    };
    configure(options);
    auto services = NodeServices::create(*server_, controller_, options);
    ASSERT_TRUE(services.ok()) << services.error().message;
    services_ = std::move(services.value());
    controller_.on_command([this](const control::Command& c, const control::CommandResult& r) {
      services_->command_applied(c, r);
      // As rbsim node wires it: a reset's time goes out on /clock at once (the loop's thread, where
      // run() made the sink).
      if (c.kind == control::CommandKind::Reset && r.successful && clock_sink_ != nullptr)
        clock_sink_->time_reset();
      const std::lock_guard lock(mu_);
      applied_.push_back(c.kind);
      recorded_.push_back(control::to_message(c, r, recorded_.size(), controller_.world_info().dt));
    });
    run_ = std::async(std::launch::async, [this] { return run(); });
    client_.emplace(participant(node_ + "_client"));
  }
  void TearDown() override {
    controller_.close("the test ended");
    if (run_.valid()) {
      EXPECT_EQ(run_.wait_for(60s), std::future_status::ready);
    }
  }

  // A derived fixture's own options (SpawnablesTest's folder).
  virtual void configure(NodeServicesOptions&) {}

  Participant participant(const std::string& name) {
    return test::participant(GetParam(), network_, kDomain, name);
  }

  // Calls <node>/<service> with `req` and decodes the reply.
  template <class Res, class Req>
  Res call(const std::string& service, const Req& req) {
    Bytes body;
    encode(req, body);
    return call_raw<Res>(service, std::string(Req::kService), body);
  }
  template <class Res>
  Res call_raw(const std::string& service, const std::string& type, const Bytes& body) {
    auto client = ServiceClient::create(*client_, "/" + node_ + "/" + service, type);
    if (!client) throw std::runtime_error(client.error().message);
    if (Status st = client.value().wait_for_server(20.0); !st) throw std::runtime_error(st.error().message);
    Result<Bytes> reply = client.value().call(body, 20.0);
    if (!reply) throw std::runtime_error(service + ": " + reply.error().message);
    Res res;
    if (Status st = decode(std::span<const std::byte>(reply.value()), res); !st)
      throw std::runtime_error(st.error().message);
    return res;
  }

  // The node's run loop: every step 200 us apart (a paced node's steps take time, so a reply sent
  // before its steps are done shows), nothing kept.
  Status run() {
    Result<Driver> driver = Driver::create(scene_);
    if (!driver) return driver.error();
    // /clock (and the scene description and body states), on the in-memory network only: /clock
    // is one global topic, which other test processes on the DDS domain publish too.
    std::unique_ptr<DdsSink> clock;
    if (GetParam() == "memory") {
      NodeOptions o;
      o.ns = node_;
      o.topics = msgs::TopicSet{}
                     .set(static_cast<std::size_t>(msgs::TopicId::Clock))
                     .set(static_cast<std::size_t>(msgs::TopicId::SceneDescription))
                     .set(static_cast<std::size_t>(msgs::TopicId::BodyStates));
      auto sink = DdsSink::create(*server_, o);
      if (!sink) return sink.error();
      clock = std::move(sink.value());
      driver.value().add(*clock);
      clock_sink_ = clock.get();
    }
    DriverOptions options;
    options.steps = kSteps;
    options.control = &controller_;
    options.pace = [](const World&) { std::this_thread::sleep_for(200us); };
    Status st = driver.value().run_pass(options);
    clock_sink_ = nullptr;
    return st;
  }

  std::uint8_t state() {
    const auto res =
        call<sim::GetSimulationStateResponse>("get_simulation_state", sim::GetSimulationStateRequest{});
    EXPECT_EQ(res.result.result, SimResult::kOk) << res.result.error_message;
    return res.state;
  }
  SimResult set_state(State s) {
    sim::SetSimulationStateRequest req;
    req.state = static_cast<std::uint8_t>(s);
    return call<SetRes>("set_simulation_state", req).result;
  }
  SimResult step(std::uint64_t n) {
    sim::StepSimulationRequest req;
    req.steps = n;
    return call<sim::StepSimulationResponse>("step_simulation", req).result;
  }
  sim::GetEntitiesStatesResponse states(const sim::EntityFilters& filters = {}) {
    sim::GetEntitiesStatesRequest req;
    req.filters = filters;
    return call<sim::GetEntitiesStatesResponse>("get_entities_states", req);
  }
  std::vector<std::string> entities(const sim::EntityFilters& filters) {
    sim::GetEntitiesRequest req;
    req.filters = filters;
    const auto res = call<sim::GetEntitiesResponse>("get_entities", req);
    EXPECT_EQ(res.result.result, SimResult::kOk) << res.result.error_message;
    return res.entities;
  }
  std::vector<control::CommandKind> applied() {
    const std::lock_guard lock(mu_);
    return applied_;
  }

  // The session's commands, as <node>/commands carried them (but those of kind `without`), applied
  // again offline: the last step's snapshot.
  test::Snapshot resimulated(std::optional<control::CommandKind> without = std::nullopt) {
    std::vector<control::ScriptedCommand> commands;
    {
      const std::lock_guard lock(mu_);
      std::uint32_t epoch = 0;  // restarts (resets, world loads) before it, as load_commands counts them
      for (std::size_t k = 0; k < recorded_.size(); ++k) {
        Result<control::Command> back = control::from_message(recorded_[k]);
        if (!back) throw std::runtime_error(back.error().message);
        const bool restarts = control::restarts_steps(back.value().kind) && recorded_[k].success;
        if (back.value().kind != without)
          commands.push_back({back.value(), recorded_[k].success, "command " + std::to_string(k), epoch});
        if (restarts) ++epoch;
      }
    }
    control::ScriptedRun run(scene_, kSteps, std::move(commands));
    std::vector<test::Snapshot> snaps = test::run(scene_, kSteps, &run.controller());
    EXPECT_TRUE(run.finish("session").ok()) << (run.mismatches().empty() ? "" : run.mismatches()[0]);
    return snaps.back();
  }
  // The live states equal, bit for bit, a snapshot's columns (x, y, theta, vx, vy, omega of every
  // body).
  static void expect_states_equal(const sim::GetEntitiesStatesResponse& live, const test::Snapshot& again) {
    const std::size_t n = live.states.size();
    ASSERT_EQ(again.state.size(), 6 * n);
    for (std::size_t b = 0; b < n; ++b) {
      EXPECT_EQ(live.states[b].position.x, again.state[0 * n + b]);
      EXPECT_EQ(live.states[b].position.y, again.state[1 * n + b]);
      EXPECT_EQ(live.states[b].orientation.z, msgs::quaternion_z(again.state[2 * n + b]).z);
      EXPECT_EQ(live.states[b].linear_velocity.x, again.state[3 * n + b]);
      EXPECT_EQ(live.states[b].linear_velocity.y, again.state[4 * n + b]);
      EXPECT_EQ(live.states[b].angular_velocity.z, again.state[5 * n + b]);
    }
  }

  const Scene scene_ = test::control_scene();
  control::Controller controller_{scene_, kSteps, control::RunSettings{1.0, 1, true}};
  std::shared_ptr<MemoryNetwork> network_ = std::make_shared<MemoryNetwork>();
  std::string node_;
  std::optional<Participant> server_, client_;
  std::unique_ptr<NodeServices> services_;
  DdsSink* clock_sink_ = nullptr;  // the run loop's thread only
  std::atomic<int> quits_{0};
  std::future<Status> run_;
  std::mutex mu_;
  std::vector<control::CommandKind> applied_;
  std::vector<msgs::CommandMessage> recorded_;  // as <node>/commands carries them
};

sim::EntityFilters named(const std::string& pattern) {
  sim::EntityFilters f;
  f.filter = pattern;
  return f;
}
sim::EntityFilters of_category(sim::Category c) {
  sim::EntityFilters f;
  f.categories = {static_cast<std::uint8_t>(c)};
  return f;
}
sim::EntityFilters within(sim::BoundsType type, std::vector<sim::Vector3> points) {
  sim::EntityFilters f;
  f.bounds.type = static_cast<std::uint8_t>(type);
  f.bounds.points = std::move(points);
  return f;
}

// The scene's world stepped `steps` times here: what the node's world holds at that step.
World stepped(const Scene& scene, std::int64_t steps) {
  Result<World> w = World::create(scene.world);
  if (!w) throw std::runtime_error(w.error().message);
  for (std::int64_t i = 0; i < steps; ++i) w.value().step();
  return std::move(w.value());
}

TEST_P(SimulationServicesTest, FeaturesListWhatWorksAndTheRestIsUnsupported) {
  const auto features =
      call<sim::GetSimulatorFeaturesResponse>("get_simulator_features", sim::GetSimulatorFeaturesRequest{});
  const std::vector<std::uint16_t> listed = features.features.features;
  const auto has = [&](sim::Feature f) {
    return std::find(listed.begin(), listed.end(), static_cast<std::uint16_t>(f)) != listed.end();
  };
  for (const sim::Feature f : {sim::Feature::Spawning,
                               sim::Feature::Deleting,
                               sim::Feature::SpawningResourceString,
                               sim::Feature::SpawningEntities,
                               sim::Feature::SimulationResetSpawned,
                               sim::Feature::EntityBounds,
                               sim::Feature::EntityBoundsBox,
                               sim::Feature::EntityCategories,
                               sim::Feature::EntityStateGetting,
                               sim::Feature::EntityStateSetting,
                               sim::Feature::EntityInfoGetting,
                               sim::Feature::SimulationReset,
                               sim::Feature::SimulationStateGetting,
                               sim::Feature::SimulationStateSetting,
                               sim::Feature::SimulationStatePause,
                               sim::Feature::StepSimulationSingle,
                               sim::Feature::StepSimulationMultiple,
                               sim::Feature::StepSimulationAction,
                               sim::Feature::WorldLoading,
                               sim::Feature::WorldResourceString,
                               sim::Feature::WorldUnloading,
                               sim::Feature::WorldInfoGetting}) {
    EXPECT_TRUE(has(f)) << static_cast<int>(f);
  }
  EXPECT_EQ(listed.size(), 22u);
  // No worlds folder: get_available_worlds is unsupported (AVAILABLE_WORLDS not listed).
  EXPECT_FALSE(has(sim::Feature::AvailableWorlds));
  EXPECT_EQ(call<sim::GetAvailableWorldsResponse>("get_available_worlds", sim::GetAvailableWorldsRequest{})
                .result.result,
            SimResult::kFeatureUnsupported);
  EXPECT_EQ(features.features.spawn_formats, std::vector<std::string>{"fosssim-fragment"});

  // What is not listed answers RESULT_FEATURE_UNSUPPORTED.
  sim::SetEntityStateRequest set;
  set.entity = "body_0";
  set.set_acceleration = true;
  EXPECT_EQ(call<sim::SetEntityStateResponse>("set_entity_state", set).result.result,
            SimResult::kFeatureUnsupported);
  EXPECT_FALSE(has(sim::Feature::EntityTags));
  sim::EntityFilters tagged;
  tagged.tags.tags = {"wheel"};
  EXPECT_EQ(states(tagged).result.result, SimResult::kFeatureUnsupported);
  EXPECT_FALSE(has(sim::Feature::EntityBoundsConvex));
  EXPECT_EQ(states(within(sim::BoundsType::ConvexHull, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}})).result.result,
            SimResult::kFeatureUnsupported);
  EXPECT_FALSE(has(sim::Feature::SimulationResetTime));
  EXPECT_FALSE(has(sim::Feature::SimulationResetState));
  // No spawnables folder (rbsim node --spawnables): get_spawnables is unsupported, a uri refused.
  EXPECT_FALSE(has(sim::Feature::Spawnables));
  const auto spawnables =
      call<sim::GetSpawnablesResponse>("get_spawnables", sim::GetSpawnablesRequest{{"/tmp"}});
  EXPECT_EQ(spawnables.result.result, SimResult::kFeatureUnsupported);
  EXPECT_NE(spawnables.result.error_message.find("--spawnables"), std::string::npos)
      << spawnables.result.error_message;
  EXPECT_TRUE(spawnables.spawnables.empty());
  sim::SpawnEntityRequest by_uri;
  by_uri.name = "ball";
  by_uri.entity_resource.uri = "ball.xml";
  const auto refused = call<sim::SpawnEntityResponse>("spawn_entity", by_uri);
  EXPECT_EQ(refused.result.result, sim::SpawnEntityResponse::kNoResource);
  EXPECT_NE(refused.result.error_message.find("--spawnables DIR"), std::string::npos)
      << refused.result.error_message;
  for (const std::uint8_t scope :
       {sim::ResetSimulationRequest::kScopeTime, sim::ResetSimulationRequest::kScopeState}) {
    sim::ResetSimulationRequest reset;
    reset.scope = scope;
    EXPECT_EQ(call<sim::ResetSimulationResponse>("reset_simulation", reset).result.result,
              SimResult::kFeatureUnsupported)
        << "scope " << int(scope);
  }
  EXPECT_TRUE(applied().empty()) << "nothing unsupported became a command";
}

TEST_P(SimulationServicesTest, StateMovesAsTheDefinitionSays) {
  EXPECT_EQ(state(), static_cast<std::uint8_t>(State::Stopped)) << "paused at step 0 before any play";
  EXPECT_EQ(set_state(State::Stopped).result, SetRes::kAlreadyInTargetState);
  EXPECT_EQ(set_state(State::NoWorld).result, SetRes::kIncorrectTransition);
  EXPECT_EQ(set_state(static_cast<State>(9)).result, SetRes::kIncorrectTransition);

  // STOPPED -> PAUSED: still at step 0, no step taken.
  EXPECT_EQ(set_state(State::Paused).result, SimResult::kOk);
  EXPECT_EQ(state(), static_cast<std::uint8_t>(State::Paused));
  EXPECT_EQ(set_state(State::Paused).result, SetRes::kAlreadyInTargetState);

  // Stepping: answered once the world reached the step (the entity's stamp says which).
  EXPECT_EQ(step(0).result, SimResult::kOperationFailed);
  EXPECT_EQ(step(1).result, SimResult::kOk);
  EXPECT_EQ(step(249).result, SimResult::kOk);
  const auto at250 = states(named("^body_0$"));
  ASSERT_EQ(at250.states.size(), 1u);
  EXPECT_EQ(at250.states[0].stamp.sec, msgs::sim_time(250, scene_.world.dt).sec);
  EXPECT_EQ(at250.states[0].stamp.nanosec, msgs::sim_time(250, scene_.world.dt).nanosec);

  // PLAYING: stepping is refused (only while paused); STOPPED from there resets to step 0.
  EXPECT_EQ(set_state(State::Playing).result, SimResult::kOk);
  EXPECT_EQ(state(), static_cast<std::uint8_t>(State::Playing));
  EXPECT_EQ(step(1).result, SimResult::kOperationFailed);
  EXPECT_EQ(set_state(State::Stopped).result, SimResult::kOk);
  EXPECT_EQ(state(), static_cast<std::uint8_t>(State::Stopped));
  const auto at0 = states(named("^body_0$"));
  ASSERT_EQ(at0.states.size(), 1u);
  EXPECT_EQ(at0.states[0].stamp.sec, 0);
  EXPECT_EQ(at0.states[0].stamp.nanosec, 0u);
  EXPECT_EQ(at0.states[0].position.x, stepped(scene_, 0).state(BodyId{0}).position.x());

  // A full reset while paused away from step 0 goes back to step 0, paused (not STOPPED).
  EXPECT_EQ(set_state(State::Paused).result, SimResult::kOk);
  EXPECT_EQ(step(3).result, SimResult::kOk);
  sim::ResetSimulationRequest reset;
  reset.scope = sim::ResetSimulationRequest::kScopeAll;
  EXPECT_EQ(call<sim::ResetSimulationResponse>("reset_simulation", reset).result.result, SimResult::kOk);
  EXPECT_EQ(state(), static_cast<std::uint8_t>(State::Paused));
  EXPECT_EQ(states(named("^body_0$")).states.at(0).stamp.nanosec, 0u);

  // STOPPED, then stepped by another front end (the node's own step service, Foxglove): PAUSED,
  // since the world left step 0.
  EXPECT_EQ(set_state(State::Stopped).result, SimResult::kOk);
  EXPECT_EQ(state(), static_cast<std::uint8_t>(State::Stopped));
  control::Command other;
  other.kind = control::CommandKind::Step;
  other.steps = 2;
  std::future<control::CommandResult> stepped_elsewhere = controller_.submit(other);
  ASSERT_EQ(stepped_elsewhere.wait_for(20s), std::future_status::ready);
  EXPECT_TRUE(stepped_elsewhere.get().successful);
  // Its reply comes at the boundary where stepping begins (still step 0): the state follows once
  // the world left step 0.
  std::uint8_t after = state();
  for (const auto end = std::chrono::steady_clock::now() + 20s;
       after != static_cast<std::uint8_t>(State::Paused) && std::chrono::steady_clock::now() < end;) {
    std::this_thread::sleep_for(5ms);
    after = state();
  }
  EXPECT_EQ(after, static_cast<std::uint8_t>(State::Paused));

  // Every change went through the controller as a command (recorded on <node>/commands).
  using K = control::CommandKind;
  EXPECT_EQ(applied(), (std::vector<K>{K::Pause, K::Step, K::Step, K::Resume, K::Step, K::Pause, K::Reset,
                                       K::Pause, K::Step, K::Reset, K::Pause, K::Reset, K::Step}));
}

// STATE_QUITTING ends the run (the node's quit), answered first; from then on the state reads
// QUITTING and no other state can be set.
TEST_P(SimulationServicesTest, QuittingEndsTheRun) {
  ASSERT_EQ(set_state(State::Paused).result, SimResult::kOk);
  EXPECT_EQ(set_state(State::Quitting).result, SimResult::kOk);
  EXPECT_EQ(quits_.load(), 1);
  ASSERT_EQ(run_.wait_for(20s), std::future_status::ready) << "the run loop ended";
  EXPECT_TRUE(run_.get().ok());
  EXPECT_EQ(state(), static_cast<std::uint8_t>(State::Quitting));
  EXPECT_EQ(set_state(State::Quitting).result, SetRes::kAlreadyInTargetState);
  EXPECT_EQ(set_state(State::Playing).result, SetRes::kIncorrectTransition);
  EXPECT_EQ(quits_.load(), 1);
}

// A full reset while paused publishes the new /clock at once (ROS time jumps back to 0), before any
// step is taken.
TEST_P(SimulationServicesTest, AResetPublishesTheNewClockAtOnce) {
  if (GetParam() != "memory") GTEST_SKIP() << "/clock is global: on DDS other test processes publish theirs";
  const msgs::TopicSpec& spec = msgs::topic(msgs::TopicId::Clock);
  auto sub = Subscription::create(*client_, spec, "/clock", qos_for(spec, 1000));
  ASSERT_TRUE(sub.ok()) << sub.error().message;
  ASSERT_EQ(set_state(State::Paused).result, SimResult::kOk);
  ASSERT_EQ(step(20).result, SimResult::kOk);
  const auto clock_ns = [](std::span<const std::byte> cdr) {
    msgs::CdrCursor c(cdr);
    std::int32_t sec = 0;
    std::uint32_t nanosec = 0;
    EXPECT_TRUE(c.read(sec) && c.read(nanosec));
    return std::int64_t{sec} * 1'000'000'000 + nanosec;
  };
  Received r;
  std::int64_t last = -1;
  while (sub.value().take(r)) last = clock_ns(r.cdr);
  EXPECT_EQ(last, static_cast<std::int64_t>(msgs::sim_time_ns(stepped(scene_, 20))));
  sim::ResetSimulationRequest reset;
  reset.scope = sim::ResetSimulationRequest::kScopeAll;
  ASSERT_EQ(call<sim::ResetSimulationResponse>("reset_simulation", reset).result.result, SimResult::kOk);
  bool back = false;
  for (int i = 0; i < 4000 && !back; ++i) {
    while (sub.value().take(r)) back |= clock_ns(r.cdr) == 0;
    if (!back) std::this_thread::sleep_for(5ms);
  }
  EXPECT_TRUE(back) << "no /clock of time 0 within 20 s of the reset";
  EXPECT_EQ(state(), static_cast<std::uint8_t>(State::Paused)) << "and no step taken";
}

TEST_P(SimulationServicesTest, EntityStatesAreTheWorldsAtTheStepReached) {
  ASSERT_EQ(set_state(State::Paused).result, SimResult::kOk);
  ASSERT_EQ(step(37).result, SimResult::kOk);
  const World w = stepped(scene_, 37);
  const auto res = states();
  ASSERT_EQ(res.result.result, SimResult::kOk) << res.result.error_message;
  ASSERT_EQ(res.entities, (std::vector<std::string>{"body_0", "body_1"}));
  ASSERT_EQ(res.states.size(), 2u);
  for (std::int32_t i = 0; i < 2; ++i) {
    const BodyId b{i};
    const BodyState st = w.state(b);
    const sim::EntityState& e = res.states[static_cast<std::size_t>(i)];
    EXPECT_EQ(e.frame_id, "world");
    EXPECT_EQ(e.stamp.nanosec, msgs::sim_time(37, scene_.world.dt).nanosec);
    EXPECT_EQ(e.position, (sim::Vector3{st.position.x(), st.position.y(), 0.0}));
    const msgs::Quaternion q = msgs::quaternion_z(st.theta);
    EXPECT_EQ(e.orientation.z, q.z);
    EXPECT_EQ(e.orientation.w, q.w);
    EXPECT_EQ(e.orientation.x, 0.0);
    EXPECT_EQ(e.linear_velocity, (sim::Vector3{st.velocity.x(), st.velocity.y(), 0.0}));
    EXPECT_EQ(e.angular_velocity, (sim::Vector3{0.0, 0.0, st.omega}));
    EXPECT_EQ(e.linear_acceleration,
              (sim::Vector3{w.force(b).x() / w.mass(b), w.force(b).y() / w.mass(b), 0.0}));
    EXPECT_EQ(e.angular_acceleration, (sim::Vector3{0.0, 0.0, w.torque(b) / w.inertia(b)}));
    EXPECT_NE(e.linear_acceleration.y, 0.0) << "gravity acts";

    sim::GetEntityStateRequest one;
    one.entity = "body_" + std::to_string(i);
    const auto single = call<sim::GetEntityStateResponse>("get_entity_state", one);
    EXPECT_EQ(single.result.result, SimResult::kOk);
    EXPECT_EQ(single.state, e);
  }
}

// SetEntityState on a moving body: applied at the boundary (paused: the current one), read back at
// once, recorded as a command, and the session re-simulated offline from those commands (as
// rbsim run --commands does with a recording) reaches the same state, bit for bit.
TEST_P(SimulationServicesTest, SetEntityStateIsACommandAndReSimulatesExactly) {
  ASSERT_EQ(set_state(State::Paused).result, SimResult::kOk);
  ASSERT_EQ(step(10).result, SimResult::kOk);
  sim::SetEntityStateRequest set;
  set.entity = "body_1";
  set.state.position = {1.25, -0.5, 0.0};
  set.state.orientation = msgs::quaternion_z(0.75);
  set.state.linear_velocity = {-2.0, 3.0, 0.0};
  set.state.angular_velocity = {0.0, 0.0, 1.5};
  set.set_pose = true;
  set.set_twist = true;
  const auto applied_set = call<sim::SetEntityStateResponse>("set_entity_state", set);
  ASSERT_EQ(applied_set.result.result, SimResult::kOk) << applied_set.result.error_message;
  sim::GetEntityStateRequest get;
  get.entity = "body_1";
  const sim::EntityState now = call<sim::GetEntityStateResponse>("get_entity_state", get).state;
  EXPECT_EQ(now.position, set.state.position);
  EXPECT_EQ(now.linear_velocity, set.state.linear_velocity);
  EXPECT_EQ(now.angular_velocity, set.state.angular_velocity);
  EXPECT_NEAR(now.orientation.z, set.state.orientation.z, 1e-15);
  EXPECT_NEAR(now.orientation.w, set.state.orientation.w, 1e-15);
  EXPECT_EQ(now.stamp.nanosec, msgs::sim_time(10, scene_.world.dt).nanosec) << "still at step 10";

  // Only the twist: the pose stays.
  sim::SetEntityStateRequest twist = set;
  twist.set_pose = false;
  twist.state.position = {99.0, 99.0, 0.0};
  twist.state.linear_velocity = {0.5, 0.0, 0.0};
  ASSERT_EQ(call<sim::SetEntityStateResponse>("set_entity_state", twist).result.result, SimResult::kOk);
  EXPECT_EQ(call<sim::GetEntityStateResponse>("get_entity_state", get).state.position, set.state.position);

  // Refused, each with its code; nothing of them applied.
  const auto refused = [&](sim::SetEntityStateRequest r) {
    return call<sim::SetEntityStateResponse>("set_entity_state", r).result.result;
  };
  using SetState = sim::SetEntityStateResponse;
  sim::SetEntityStateRequest bad = set;
  bad.state.orientation = {0.5, 0.0, 0.0, std::sqrt(0.75)};  // a rotation about x
  EXPECT_EQ(refused(bad), SetState::kInvalidPose);
  bad.state.orientation = {0.0, 0.0, 0.0, 2.0};  // not unit
  EXPECT_EQ(refused(bad), SetState::kInvalidPose);
  bad.state.orientation = msgs::quaternion_z(0.1);
  bad.state.position.x = std::nan("");
  EXPECT_EQ(refused(bad), SetState::kInvalidPose);
  bad.state.position = {0.0, 0.0, 1.0};  // off the plane
  EXPECT_EQ(refused(bad), SetState::kInvalidPose);
  bad = set;
  bad.state.angular_velocity = {1.0, 0.0, 0.0};
  EXPECT_EQ(refused(bad), SimResult::kOperationFailed);
  bad = set;
  bad.state.linear_velocity = {1e300, 0.0, 0.0};  // past what the run can report: the controller refuses
  EXPECT_EQ(refused(bad), SimResult::kOperationFailed);
  bad = set;
  bad.state.frame_id = "map";
  EXPECT_EQ(refused(bad), SimResult::kOperationFailed);
  bad = set;
  bad.entity = "body_2";
  EXPECT_EQ(refused(bad), SimResult::kNotFound);
  ASSERT_EQ(step(20).result, SimResult::kOk);
  const auto live = states();
  ASSERT_EQ(live.states.size(), 2u);

  // The session's commands, as /NS/commands carries them, applied again offline.
  const test::Snapshot again = resimulated();
  ASSERT_EQ(again.step, 30);
  expect_states_equal(live, again);
  EXPECT_NE(resimulated(control::CommandKind::SetState).state, again.state)
      << "without the set, the run differs";
}

sim::SpawnEntityRequest spawn_request(std::string name, std::string resource, double x, double y,
                                      double theta) {
  sim::SpawnEntityRequest req;
  req.name = std::move(name);
  req.entity_resource.resource_string = std::move(resource);
  req.initial_pose.position = {x, y, 0.0};
  req.initial_pose.orientation = msgs::quaternion_z(theta);
  return req;
}

TEST_P(SimulationServicesTest, SpawnAndDeleteAreCommandsAndReSimulateExactly) {
  ASSERT_EQ(set_state(State::Paused).result, SimResult::kOk);
  ASSERT_EQ(step(10).result, SimResult::kOk);
  const auto spawn = [&](const sim::SpawnEntityRequest& req) {
    return call<sim::SpawnEntityResponse>("spawn_entity", req);
  };
  using Spawn = sim::SpawnEntityResponse;
  const Spawn first = spawn(spawn_request("ball", test::kFragment, 1.5, 6.0, 0.4));
  ASSERT_EQ(first.result.result, SimResult::kOk) << first.result.error_message;
  EXPECT_EQ(first.entity_name, "ball");
  // While paused the spawn shows at once: its pose as asked, its velocities the fragment's.
  sim::GetEntityStateRequest get;
  get.entity = "ball";
  const auto placed = call<sim::GetEntityStateResponse>("get_entity_state", get);
  ASSERT_EQ(placed.result.result, SimResult::kOk) << placed.result.error_message;
  EXPECT_EQ(placed.state.position, (sim::Vector3{1.5, 6.0, 0.0}));
  EXPECT_NEAR(placed.state.orientation.z, msgs::quaternion_z(0.4).z, 1e-15);
  EXPECT_EQ(placed.state.linear_velocity, (sim::Vector3{0.25, -0.5, 0.0}));
  EXPECT_EQ(placed.state.angular_velocity, (sim::Vector3{0.0, 0.0, 0.75}));
  EXPECT_EQ(placed.state.stamp.nanosec, msgs::sim_time(10, scene_.world.dt).nanosec);
  EXPECT_EQ(entities({}), (std::vector<std::string>{"body_0", "body_1", "ball"}));

  // Names: unique, renamed when allowed, in a namespace; each refusal with its code.
  EXPECT_EQ(spawn(spawn_request("ball", test::kFragment, 0, 0, 0)).result.result, Spawn::kNameNotUnique);
  sim::SpawnEntityRequest again = spawn_request("ball", test::kFragment, -3.0, 1.0, 0.0);
  again.allow_renaming = true;
  EXPECT_EQ(spawn(again).entity_name, "ball_1");
  sim::SpawnEntityRequest in_ns = spawn_request("bot", test::kFragment, 3.0, 1.0, 0.0);
  in_ns.entity_namespace = "/team";
  EXPECT_EQ(spawn(in_ns).entity_name, "team/bot");
  // A fragment of more than the 64 KiB other services read is read (spawned); one over the
  // fragment limit is answered in words, not dropped unread.
  const std::string padded = std::string(test::kFragment) + "<!--" + std::string(200000, '-') + "-->";
  EXPECT_EQ(spawn(spawn_request("padded", padded, 4.0, 9.0, 0.0)).result.result, SimResult::kOk);
  sim::DeleteEntityRequest unpad;
  unpad.entity = "padded";
  EXPECT_EQ(call<sim::DeleteEntityResponse>("delete_entity", unpad).result.result, SimResult::kOk);
  const std::string huge = std::string(test::kFragment) + "<!--" + std::string(1200000, '-') + "-->";
  const Spawn over = spawn(spawn_request("huge", huge, 4.0, 9.0, 0.0));
  EXPECT_EQ(over.result.result, Spawn::kResourceParseError) << over.result.error_message;
  for (const char* bad : {"body_7", "9lives", "a b", "a//b", ""}) {  // "": and allow_renaming false
    EXPECT_EQ(spawn(spawn_request(bad, test::kFragment, 0, 0, 0)).result.result, Spawn::kNameInvalid) << bad;
  }
  in_ns.entity_namespace = "team ns";
  EXPECT_EQ(spawn(in_ns).result.result, Spawn::kNamespaceInvalid);
  sim::SpawnEntityRequest by_uri = spawn_request("u", "", 0, 0, 0);
  by_uri.entity_resource.uri = "file:///etc/passwd";
  EXPECT_EQ(spawn(by_uri).result.result, Spawn::kNoResource);
  EXPECT_EQ(spawn(spawn_request("e", "", 0, 0, 0)).result.result, Spawn::kNoResource);
  const Spawn unparsed = spawn(spawn_request("p", "<scene>\n<rigidbodyvertex x=\"0\"/>\n</scene>", 0, 0, 0));
  EXPECT_EQ(unparsed.result.result, Spawn::kResourceParseError);
  EXPECT_NE(unparsed.result.error_message.find("resource_string:2"), std::string::npos)
      << unparsed.result.error_message;
  std::string missing = test::kFragment;
  missing.replace(missing.find("body_1"), 6, "nobody");
  EXPECT_EQ(spawn(spawn_request("m", missing, 0, 0, 0)).result.result, Spawn::kMissingAssets);
  sim::SpawnEntityRequest off_plane = spawn_request("z", test::kFragment, 0, 0, 0);
  off_plane.initial_pose.position.z = 1.0;
  EXPECT_EQ(spawn(off_plane).result.result, Spawn::kInvalidPose);
  off_plane.initial_pose.position.z = 0.0;
  off_plane.initial_pose.frame_id = "map";
  EXPECT_EQ(spawn(off_plane).result.result, Spawn::kInvalidPose);

  // Deleting a scene body takes its springs with it, and the reply says which.
  sim::DeleteEntityRequest del;
  del.entity = "body_0";
  const auto deleted = call<sim::DeleteEntityResponse>("delete_entity", del);
  ASSERT_EQ(deleted.result.result, SimResult::kOk) << deleted.result.error_message;
  EXPECT_NE(deleted.result.error_message.find("spring"), std::string::npos) << deleted.result.error_message;
  EXPECT_EQ(call<sim::DeleteEntityResponse>("delete_entity", del).result.result, SimResult::kNotFound);
  get.entity = "body_0";
  EXPECT_EQ(call<sim::GetEntityStateResponse>("get_entity_state", get).result.result, SimResult::kNotFound);
  EXPECT_EQ(entities({}), (std::vector<std::string>{"body_1", "ball", "ball_1", "team/bot"}));
  EXPECT_EQ(entities(named("^ball")), (std::vector<std::string>{"ball", "ball_1"}));
  ASSERT_EQ(step(20).result, SimResult::kOk);
  const auto live = states();
  ASSERT_EQ(live.states.size(), 4u);

  // The session's commands, as /NS/commands carries them, applied again offline: the same bits.
  const test::Snapshot rerun = resimulated();
  ASSERT_EQ(rerun.step, 30);
  expect_states_equal(live, rerun);

  // SCOPE_SPAWNED: what was spawned goes, the scene's bodies stay as they are (body_0 stays deleted).
  sim::ResetSimulationRequest reset;
  reset.scope = sim::ResetSimulationRequest::kScopeSpawned;
  const auto body_1 = [&] {
    sim::GetEntityStateRequest g;
    g.entity = "body_1";
    return call<sim::GetEntityStateResponse>("get_entity_state", g).state;
  };
  const sim::EntityState before = body_1();
  ASSERT_EQ(call<sim::ResetSimulationResponse>("reset_simulation", reset).result.result, SimResult::kOk);
  EXPECT_EQ(entities({}), std::vector<std::string>{"body_1"});
  EXPECT_EQ(body_1(), before);
  // A name once used is never given again.
  EXPECT_EQ(spawn(spawn_request("ball", test::kFragment, 0, 0, 0)).result.result, Spawn::kNameNotUnique);
}

// While paused, a spawn and a delete show at once on the node's topics: the scene description
// again (latched) with the world's bodies as they now are, and the current step's body states
// with their ids, before any step.
TEST_P(SimulationServicesTest, ASpawnOrDeleteWhilePausedPublishesTheChangedWorldAtOnce) {
  if (GetParam() != "memory") GTEST_SKIP() << "the node's topics are published on the in-memory network";
  const msgs::TopicSpec& scene_spec = msgs::topic(msgs::TopicId::SceneDescription);
  const msgs::TopicSpec& states_spec = msgs::topic(msgs::TopicId::BodyStates);
  auto scenes = Subscription::create(*client_, scene_spec, msgs::topic_name(scene_spec, node_),
                                     qos_for(scene_spec, 100));
  auto bodies = Subscription::create(*client_, states_spec, msgs::topic_name(states_spec, node_),
                                     qos_for(states_spec, 1000));
  ASSERT_TRUE(scenes.ok() && bodies.ok());
  ASSERT_EQ(set_state(State::Paused).result, SimResult::kOk);
  ASSERT_EQ(step(10).result, SimResult::kOk);
  // The last scene description and body states received, waiting (bounded) for ones with
  // `n` bodies.
  const auto wait_for = [&](std::size_t n) {
    std::optional<msgs::SceneMessage> scene;
    msgs::BodyStatesMessage states;
    Received r;
    for (int i = 0; i < 4000; ++i) {
      while (scenes.value().take(r)) {
        Result<msgs::SceneMessage> m = msgs::decode_scene(r.cdr);
        if (m) scene = std::move(m.value());
      }
      while (bodies.value().take(r)) EXPECT_TRUE(msgs::decode_body_states(r.cdr, states).ok());
      if (scene && scene->bodies.size() == n && states.bodies.size() == n) break;
      std::this_thread::sleep_for(5ms);
    }
    return std::pair{scene, states};
  };
  auto [before, at10] = wait_for(2);
  ASSERT_TRUE(before.has_value());
  EXPECT_EQ(at10.step, 10u);

  const auto spawned =
      call<sim::SpawnEntityResponse>("spawn_entity", spawn_request("ball", test::kFragment, 1.5, 6.0, 0.4));
  ASSERT_EQ(spawned.result.result, SimResult::kOk) << spawned.result.error_message;
  auto [grown, now] = wait_for(3);
  ASSERT_TRUE(grown.has_value());
  ASSERT_EQ(grown->bodies.size(), 3u) << "no scene description with the spawned body within 20 s";
  EXPECT_EQ(grown->bodies[2].mass, 3.0);
  EXPECT_EQ(grown->bodies[2].hull.size(), 3u);
  EXPECT_EQ(grown->springs.size(), before->springs.size() + 2);
  ASSERT_EQ(now.bodies.size(), 3u);
  EXPECT_EQ(now.step, 10u) << "the same step, not a step on";
  EXPECT_EQ(now.bodies[2].id, 2);
  EXPECT_EQ(now.bodies[2].state.position, Vec2(1.5, 6.0));

  sim::DeleteEntityRequest del;
  del.entity = "body_0";
  ASSERT_EQ(call<sim::DeleteEntityResponse>("delete_entity", del).result.result, SimResult::kOk);
  auto [shrunk, after] = wait_for(2);
  ASSERT_TRUE(shrunk.has_value());
  ASSERT_EQ(after.bodies.size(), 2u);
  EXPECT_EQ(after.bodies[0].id, 1);
  EXPECT_EQ(after.bodies[1].id, 2);
  EXPECT_EQ(shrunk->bodies[1].mass, 3.0);
  EXPECT_EQ(after.step, 10u);
}

TEST_P(SimulationServicesTest, FiltersSelectByNameCategoryAndBounds) {
  const World w = stepped(scene_, 0);
  EXPECT_EQ(entities(named("1$")), std::vector<std::string>{"body_1"});
  EXPECT_EQ(entities(named("^body_[0-9]+$")), (std::vector<std::string>{"body_0", "body_1"}));
  EXPECT_EQ(entities(of_category(sim::Category::DynamicObject)),
            (std::vector<std::string>{"body_0", "body_1"}));
  EXPECT_TRUE(entities(of_category(sim::Category::Robot)).empty());

  // Body 0 is the square x in [-3, -1], body 1 the triangle (2, -1), (2, 1), (4, 0).
  EXPECT_EQ(entities(within(sim::BoundsType::Sphere, {{-2.0, 0.0, 0.0}, {0.1, 0.0, 0.0}})),
            std::vector<std::string>{"body_0"});
  EXPECT_EQ(entities(within(sim::BoundsType::Sphere, {{0.5, 0.0, 0.0}, {1.6, 0.0, 0.0}})),
            (std::vector<std::string>{"body_0", "body_1"}));
  EXPECT_TRUE(entities(within(sim::BoundsType::Sphere, {{0.5, 0.0, 0.0}, {1.4, 0.0, 0.0}})).empty());
  EXPECT_TRUE(entities(within(sim::BoundsType::Sphere, {{-2.0, 0.0, 5.0}, {1.0, 0.0, 0.0}})).empty())
      << "the sphere does not reach the plane z = 0";
  EXPECT_EQ(entities(within(sim::BoundsType::Box, {{3.9, 0.5, 1.0}, {3.0, -0.5, -1.0}})),
            std::vector<std::string>{"body_1"});
  // The triangle's box holds (3.9, 0.9), the triangle does not: exact, not by bounding box.
  EXPECT_TRUE(entities(within(sim::BoundsType::Box, {{3.8, 0.8, 0.0}, {3.9, 0.9, 0.0}})).empty());

  // Refused input.
  EXPECT_EQ(states(named("(")).result.result, SimResult::kOperationFailed);
  EXPECT_EQ(states(named(std::string(300, 'a'))).result.result, SimResult::kOperationFailed);
  EXPECT_EQ(states(within(sim::BoundsType::Box, {{0, 0, 0}})).result.result, SimResult::kOperationFailed);
  EXPECT_EQ(states(within(sim::BoundsType::Sphere, {{0, 0, 0}, {-1, 0, 0}})).result.result,
            SimResult::kOperationFailed);
  EXPECT_EQ(states(within(sim::BoundsType::Box, {{0, 0, 0}, {std::nan(""), 0, 0}})).result.result,
            SimResult::kOperationFailed);
  EXPECT_EQ(states(within(static_cast<sim::BoundsType>(7), {})).result.result, SimResult::kOperationFailed);

  // One entity: info, bounds in the body's frame, and names no body has.
  sim::GetEntityInfoRequest info;
  info.entity = "body_1";
  const auto got = call<sim::GetEntityInfoResponse>("get_entity_info", info);
  EXPECT_EQ(got.result.result, SimResult::kOk);
  EXPECT_EQ(got.info.category, static_cast<std::uint8_t>(sim::Category::DynamicObject));
  EXPECT_NE(got.info.description.find("3 point masses"), std::string::npos) << got.info.description;
  sim::GetEntityBoundsRequest bounds;
  bounds.entity = "body_0";
  const auto box = call<sim::GetEntityBoundsResponse>("get_entity_bounds", bounds);
  ASSERT_EQ(box.result.result, SimResult::kOk);
  ASSERT_EQ(box.bounds.points.size(), 2u);
  EXPECT_EQ(box.bounds.type, static_cast<std::uint8_t>(sim::BoundsType::Box));
  double lo_x = 1e9, hi_y = -1e9;
  for (const Vec2& v : w.hull(BodyId{0})) {
    lo_x = std::min(lo_x, v.x());
    hi_y = std::max(hi_y, v.y());
  }
  EXPECT_EQ(box.bounds.points[0].y, hi_y);
  EXPECT_EQ(box.bounds.points[1].x, lo_x);
  for (const std::string name : {"body_2", "body_01", "body_", "body_-1", "Body_0", "body_99999999999"}) {
    sim::GetEntityStateRequest req;
    req.entity = name;
    EXPECT_EQ(call<sim::GetEntityStateResponse>("get_entity_state", req).result.result, SimResult::kNotFound)
        << name;
  }
}

TEST_P(SimulationServicesTest, AMalformedRequestIsAnsweredAsFailed) {
  const Bytes garbage{std::byte{0}, std::byte{1}, std::byte{0}, std::byte{0}, std::byte{0xff}};
  const auto res = call_raw<sim::GetEntityStateResponse>(
      "get_entity_state", std::string(sim::GetEntityStateRequest::kService), garbage);
  EXPECT_EQ(res.result.result, SimResult::kOperationFailed);
  EXPECT_NE(res.result.error_message.find("GetEntityState request"), std::string::npos)
      << res.result.error_message;
}

// Service introspection follows the parameter service_configure_introspection, set through the
// node's own parameter service and applied at a step boundary: off (no publisher), contents (the
// request and the response in the events), metadata (neither), off again (the publisher gone).
TEST_P(SimulationServicesTest, IntrospectionFollowsItsParameter) {
  const std::string service(sim::GetEntityStateRequest::kService);
  auto sub = Subscription::create(
      *client_, RawTopic{"/" + node_ + "/get_entity_state/_service_event", msgs::service_event_type(service)},
      service_event_qos());
  ASSERT_TRUE(sub.ok());
  Result<msgs::ServiceEventCodec> codec = msgs::ServiceEventCodec::create(service);
  ASSERT_TRUE(codec.ok());
  const auto get = [&](const std::string& entity) {
    sim::GetEntityStateRequest req;
    req.entity = entity;
    return call<sim::GetEntityStateResponse>("get_entity_state", req);
  };
  const auto introspection = [&](const char* word) {
    msgs::SetParametersRequest req;
    req.parameters = {{"service_configure_introspection", msgs::ParameterValue::of_string(word)}};
    const auto res = call<msgs::SetParametersResponse>("set_parameters", req);
    ASSERT_EQ(res.results.size(), 1u);
    EXPECT_TRUE(res.results[0].successful) << res.results[0].reason;
  };
  // Events until `count` came (bounded), decoded.
  const auto events = [&](std::size_t count) {
    std::vector<std::pair<msgs::ServiceEventInfo, std::pair<Bytes, Bytes>>> out;
    const auto end = std::chrono::steady_clock::now() + 20s;
    Received r;
    while (out.size() < count && std::chrono::steady_clock::now() < end) {
      if (!sub->take(r)) {
        std::this_thread::sleep_for(2ms);
        continue;
      }
      msgs::ServiceEventInfo info;
      Bytes req, res;
      EXPECT_TRUE(codec.value().decode(r.cdr, info, req, res).ok());
      out.push_back({info, {std::move(req), std::move(res)}});
    }
    return out;
  };

  const auto until = [](auto done) {  // bounded: DDS matching takes a moment
    const auto end = std::chrono::steady_clock::now() + 20s;
    while (!done() && std::chrono::steady_clock::now() < end) std::this_thread::sleep_for(2ms);
    return done();
  };
  get("body_0");  // off: no publisher, so no event of it can come later
  EXPECT_EQ(sub->matched(), 0);
  introspection("contents");
  ASSERT_TRUE(until([&] { return sub->matched() == 1; }));
  const sim::GetEntityStateResponse answered = get("body_1");
  auto got = events(2);
  ASSERT_EQ(got.size(), 2u);
  EXPECT_EQ(got[0].first.event_type, msgs::ServiceEventType::RequestReceived);
  sim::GetEntityStateRequest req;
  ASSERT_TRUE(decode(std::span<const std::byte>(got[0].second.first), req).ok());
  EXPECT_EQ(req.entity, "body_1");
  EXPECT_EQ(got[1].first.event_type, msgs::ServiceEventType::ResponseSent);
  Bytes answered_cdr;
  encode(answered, answered_cdr);
  EXPECT_EQ(got[1].second.second, answered_cdr);

  introspection("metadata");
  get("body_0");
  got = events(2);
  ASSERT_EQ(got.size(), 2u);
  for (const auto& [info, parts] : got) {
    EXPECT_TRUE(parts.first.empty());
    EXPECT_TRUE(parts.second.empty());
  }
  EXPECT_EQ(got[0].first.client_gid, got[1].first.client_gid);
  EXPECT_EQ(got[0].first.sequence_number, got[1].first.sequence_number);

  introspection("disabled");
  EXPECT_TRUE(until([&] { return sub->matched() == 0; }));
  // Every service's events: get_entity_state's four; set_parameters' two while it was on (the call
  // to metadata) and the request of the call to disabled (its reply came after the switch); none
  // of the call that turned it on (its request came while off, and a call's events follow the
  // state it found).
  EXPECT_EQ(services_->counters().service_events, 7u);
}

// The node's other front ends (its Foxglove server) run these very handlers: the catalogue's
// simulation_interfaces part, answering as the DDS services do, their commands recorded with the
// front end's source.
TEST_P(SimulationServicesTest, SimulationHandlersAreTheServedOnesWithTheirSource) {
  const std::vector<std::string> want = {
      "get_simulator_features", "get_simulation_state", "set_simulation_state", "reset_simulation",
      "step_simulation",        "get_entities",         "get_entities_states",  "get_entity_info",
      "get_entity_state",       "get_entity_bounds",    "set_entity_state",     "spawn_entity",
      "spawn_entities",         "delete_entity",        "get_spawnables",       "load_world",
      "unload_world",           "get_current_world",    "get_available_worlds"};
  std::vector<std::string> listed, handled, names;
  for (const NodeServices::Served& s : NodeServices::simulation_catalogue()) {
    listed.push_back(s.name + " " + s.type);
    names.push_back(s.name);
  }
  const std::vector<NodeServices::Handled> handlers = services_->simulation_handlers("foxglove");
  for (const NodeServices::Handled& h : handlers) handled.push_back(h.name + " " + h.type);
  EXPECT_EQ(handled, listed);
  std::vector<std::string> sorted_names = names, sorted_want = want;
  std::sort(sorted_names.begin(), sorted_names.end());
  std::sort(sorted_want.begin(), sorted_want.end());
  EXPECT_EQ(sorted_names, sorted_want);
  const auto handler = [&](std::string_view name) -> const ServiceServer::Handler& {
    for (const NodeServices::Handled& h : handlers) {
      if (h.name == name) return h.handler;
    }
    throw std::runtime_error("no handler " + std::string(name));
  };

  ASSERT_EQ(set_state(State::Paused).result, SimResult::kOk);  // over DDS
  sim::StepSimulationRequest step_req;
  step_req.steps = 3;
  Bytes body, reply;
  encode(step_req, body);
  ASSERT_TRUE(handler("step_simulation")(RequestHeader{}, body, reply));
  sim::StepSimulationResponse stepped_res;
  ASSERT_TRUE(decode(std::span<const std::byte>(reply), stepped_res).ok());
  EXPECT_EQ(stepped_res.result.result, SimResult::kOk) << stepped_res.result.error_message;

  sim::GetEntityStateRequest get;
  get.entity = "body_1";
  encode(get, body);
  ASSERT_TRUE(handler("get_entity_state")(RequestHeader{}, body, reply));
  sim::GetEntityStateResponse here;
  ASSERT_TRUE(decode(std::span<const std::byte>(reply), here).ok());
  const auto over_dds = call<sim::GetEntityStateResponse>("get_entity_state", get);
  EXPECT_EQ(here.result.result, SimResult::kOk) << here.result.error_message;
  EXPECT_EQ(here.state, over_dds.state);
  const World w = stepped(scene_, 3);
  EXPECT_EQ(here.state.position.x, w.x()[1]);
  EXPECT_EQ(here.state.position.y, w.y()[1]);

  const std::lock_guard lock(mu_);
  ASSERT_EQ(recorded_.size(), 2u);
  EXPECT_EQ(recorded_[0].source, "ros2 service");  // the pause, over DDS
  EXPECT_EQ(recorded_[1].source, "foxglove");      // the step, through the handler
  EXPECT_EQ(recorded_[1].steps, 3u);
}

// rbsim bridge's forward of a simulation service: the request's CDR to the node's service, the
// reply's back as it came; a node that serves none fails the call naming the service, bounded.
TEST_P(SimulationServicesTest, ForwardedServiceCallsTheNodesServiceWithRawCdr) {
  const std::string type(sim::GetSimulationStateRequest::kService);
  auto forward = bridge::ForwardedService::create(*client_, "/" + node_, "get_simulation_state", type);
  ASSERT_TRUE(forward.ok()) << forward.error().message;
  Bytes body;
  encode(sim::GetSimulationStateRequest{}, body);
  Result<Bytes> reply = forward.value()->call(body);
  ASSERT_TRUE(reply.ok()) << reply.error().message;
  sim::GetSimulationStateResponse res;
  ASSERT_TRUE(decode(std::span<const std::byte>(reply.value()), res).ok());
  EXPECT_EQ(res.result.result, SimResult::kOk);
  EXPECT_EQ(res.state, static_cast<std::uint8_t>(State::Stopped));

  bridge::ForwardOptions quick;
  quick.match_timeout_s = 0.2;
  auto absent = bridge::ForwardedService::create(*client_, "/" + node_ + "_absent", "get_simulation_state",
                                                 type, quick);
  ASSERT_TRUE(absent.ok()) << absent.error().message;
  const auto t0 = std::chrono::steady_clock::now();
  Result<Bytes> none = absent.value()->call(body);
  ASSERT_FALSE(none.ok());
  EXPECT_NE(none.error().message.find("/" + node_ + "_absent/get_simulation_state: "), std::string::npos)
      << none.error().message;
  EXPECT_LT(std::chrono::steady_clock::now() - t0, 5s);
}

INSTANTIATE_TEST_SUITE_P(Middleware, SimulationServicesTest, ::testing::Values("dds", "memory"),
                         [](const ::testing::TestParamInfo<std::string>& p) { return p.param; });

// ---------------------------------------------------------------------------------------------
// Spawning from the node's spawnables folder (rbsim node --spawnables DIR), spawn_entities and
// get_spawnables: a folder of fragments beside every kind of file its policy refuses.

// A fragment of one body, no spring, a 2 m square about (1, 1).
constexpr const char* kSquare = R"(<scene>
  <description text="a square"/>
  <rigidbodyvertex x="0" y="0" m="1"/><rigidbodyvertex x="0" y="2" m="1"/>
  <rigidbodyvertex x="2" y="2" m="1"/><rigidbodyvertex x="2" y="0" m="1"/>
  <rigidbody p="0" p="1" p="2" p="3" vx="0.5" vy="0" omega="0.25" r="0.1"/>
</scene>)";

class SpawnablesTest : public SimulationServicesTest {
 protected:
  void SetUp() override {
    namespace fs = std::filesystem;
    root_ = fs::path(::testing::TempDir()) / test::node_name("rbsim_spawnables");
    folder_ = root_ / "spawnables";
    fs::remove_all(root_);
    fs::create_directories(folder_ / "sub");
    fs::create_directories(folder_ / "dir.xml");
    write(folder_ / "ball.xml", test::kFragment);
    write(folder_ / "square.xml", kSquare);
    write(folder_ / "sub" / "inner.xml", kSquare);
    write(folder_ / "notes.txt", "not a fragment");
    write(folder_ / "bad.xml", "<scene>\n<rigidbodyvertex x=\"0\"/>\n</scene>\n");
    write(folder_ / "huge.xml", std::string(FragmentLimits{}.max_bytes + 1, ' '));
    write(root_ / "outside.xml", kSquare);
    fs::create_symlink(folder_ / "ball.xml", folder_ / "link_in.xml");
    fs::create_symlink(root_ / "outside.xml", folder_ / "link_out.xml");
    fs::create_directory_symlink(folder_ / "sub", folder_ / "linkdir");
    ASSERT_EQ(::mkfifo((folder_ / "fifo.xml").c_str(), 0600), 0) << std::strerror(errno);
    // A device inside the folder where this process may make one (as root): /dev/null's.
    has_device_ = ::mknod((folder_ / "null.xml").c_str(), S_IFCHR | 0600, makedev(1, 3)) == 0;
    SimulationServicesTest::SetUp();
  }
  void TearDown() override {
    SimulationServicesTest::TearDown();
    std::error_code ec;
    std::filesystem::remove_all(root_, ec);
  }
  void configure(NodeServicesOptions& options) override { options.spawnables = {folder_.string()}; }

  static void write(const std::filesystem::path& path, const std::string& text) {
    std::ofstream out(path, std::ios::binary);
    out << text;
    if (!out) throw std::runtime_error("cannot write " + path.string());
  }
  sim::SpawnEntityResponse spawn(const sim::SpawnEntityRequest& req) {
    return call<sim::SpawnEntityResponse>("spawn_entity", req);
  }
  static sim::SpawnEntityRequest by_uri(std::string name, std::string uri, double x = 0, double y = 0) {
    sim::SpawnEntityRequest req = spawn_request(std::move(name), "", x, y, 0.0);
    req.allow_renaming = req.name.empty();  // a name generated
    req.entity_resource.uri = std::move(uri);
    return req;
  }
  static sim::SpawnEntity entity(std::string name, std::string uri, std::string resource, double x) {
    sim::SpawnEntity e;
    e.allow_renaming = name.empty();  // a name generated
    e.name = std::move(name);
    e.entity_resource.uri = std::move(uri);
    e.entity_resource.resource_string = std::move(resource);
    e.initial_pose.position = {x, 1.0, 0.0};
    e.initial_pose.orientation = msgs::quaternion_z(0.0);
    return e;
  }
  // The spawn_entity commands of the session as <node>/commands carried them.
  std::vector<msgs::CommandMessage> spawns() {
    const std::lock_guard lock(mu_);
    std::vector<msgs::CommandMessage> out;
    for (const msgs::CommandMessage& m : recorded_) {
      if (m.kind == msgs::CommandMessage::SpawnEntity) out.push_back(m);
    }
    return out;
  }

  std::filesystem::path root_, folder_;
  bool has_device_ = false;
};

TEST_P(SpawnablesTest, AUriInsideTheFolderSpawnsItsTextAndReSimulatesExactly) {
  ASSERT_EQ(set_state(State::Paused).result, SimResult::kOk);
  ASSERT_EQ(step(10).result, SimResult::kOk);
  // Relative to the folder (a resource_string beside a uri is ignored, as Resource.msg says).
  sim::SpawnEntityRequest rel = by_uri("ball", "ball.xml", 1.5, 6.0);
  rel.initial_pose.orientation = msgs::quaternion_z(0.4);
  rel.entity_resource.resource_string = "ignored: the uri is given";
  const auto ball = spawn(rel);
  ASSERT_EQ(ball.result.result, SimResult::kOk) << ball.result.error_message;
  EXPECT_EQ(ball.entity_name, "ball");
  sim::GetEntityStateRequest get;
  get.entity = "ball";
  const auto placed = call<sim::GetEntityStateResponse>("get_entity_state", get);
  ASSERT_EQ(placed.result.result, SimResult::kOk) << placed.result.error_message;
  EXPECT_EQ(placed.state.position, (sim::Vector3{1.5, 6.0, 0.0}));
  EXPECT_EQ(placed.state.linear_velocity, (sim::Vector3{0.25, -0.5, 0.0})) << "the file's fragment";
  // An absolute path inside the folder, a file:// URI of one in a subfolder.
  const auto square = spawn(by_uri("square", (folder_ / "square.xml").string(), -3.0, 1.0));
  ASSERT_EQ(square.result.result, SimResult::kOk) << square.result.error_message;
  const std::string inner_uri = "file://" + (folder_ / "sub" / "inner.xml").string();
  const auto inner = spawn(by_uri("inner", inner_uri, 3.0, 1.0));
  ASSERT_EQ(inner.result.result, SimResult::kOk) << inner.result.error_message;
  EXPECT_EQ(entities({}), (std::vector<std::string>{"body_0", "body_1", "ball", "square", "inner"}));

  // The commands carry the files' texts (and the uris, for the record): a re-run needs no file.
  const std::vector<msgs::CommandMessage> recorded = spawns();
  ASSERT_EQ(recorded.size(), 3u);
  const std::vector<std::pair<std::string, std::string>> want = {
      {"ball.xml", test::kFragment}, {(folder_ / "square.xml").string(), kSquare}, {inner_uri, kSquare}};
  for (std::size_t k = 0; k < recorded.size(); ++k) {
    Result<control::Command> back = control::from_message(recorded[k]);
    ASSERT_TRUE(back.ok()) << back.error().message;
    EXPECT_EQ(back.value().spawn.uri, want[k].first);
    EXPECT_EQ(back.value().spawn.resource, want[k].second);
  }
  ASSERT_EQ(step(20).result, SimResult::kOk);
  const auto live = states();
  ASSERT_EQ(live.states.size(), 5u);
  std::filesystem::remove_all(folder_);
  const test::Snapshot rerun = resimulated();
  ASSERT_EQ(rerun.step, 30);
  expect_states_equal(live, rerun);
}

TEST_P(SpawnablesTest, EveryUriOutsideThePolicyIsRefusedNamingTheUriAndTheRule) {
  using Spawn = sim::SpawnEntityResponse;
  struct Case {
    std::string uri;
    std::uint8_t code;
    std::string says;
  };
  const std::string outside = (root_ / "outside.xml").string();
  std::vector<Case> cases = {
      {"../outside.xml", Spawn::kNoResource, "'..' is not allowed"},
      {"sub/../../outside.xml", Spawn::kNoResource, "'..' is not allowed"},
      {outside, Spawn::kNoResource, "outside the spawnables folder"},
      {"file://" + outside, Spawn::kNoResource, "outside the spawnables folder"},
      {"link_out.xml", Spawn::kNoResource, "link_out.xml is a symbolic link"},
      {"link_in.xml", Spawn::kNoResource, "link_in.xml is a symbolic link"},
      {"linkdir/inner.xml", Spawn::kNoResource, "linkdir is a symbolic link"},
      {"fifo.xml", Spawn::kNoResource, "fifo.xml is a FIFO, not a regular file"},
      {"/dev/null", Spawn::kNoResource, "outside the spawnables folder"},
      {"file:///dev/zero", Spawn::kNoResource, "outside the spawnables folder"},
      {"dir.xml", Spawn::kNoResource, "dir.xml is a directory, not a regular file"},
      {folder_.string(), Spawn::kNoResource, "the spawnables folder itself"},
      {"missing.xml", Spawn::kNoResource, "no such file"},
      {"http://example.com/ball.xml", Spawn::kNoResource, "only a path or a file:// URI"},
      {"file://elsewhere/ball.xml", Spawn::kNoResource, "an absolute path on this host"},
      {"huge.xml", Spawn::kResourceParseError, "more than 1,048,576"},
      {"bad.xml", Spawn::kResourceParseError, "bad.xml:2: "},
  };
  if (has_device_) cases.push_back({"null.xml", Spawn::kNoResource, "null.xml is a character device"});
  const auto t0 = std::chrono::steady_clock::now();
  for (const Case& c : cases) {
    const Spawn res = spawn(by_uri("x", c.uri));
    EXPECT_EQ(res.result.result, c.code) << c.uri << ": " << res.result.error_message;
    EXPECT_NE(res.result.error_message.find(c.says), std::string::npos)
        << c.uri << ": " << res.result.error_message;
    if (c.code == Spawn::kNoResource) {
      EXPECT_NE(res.result.error_message.find("uri '" + c.uri + "'"), std::string::npos)
          << res.result.error_message;
    }
    EXPECT_TRUE(res.entity_name.empty());
  }
  EXPECT_LT(std::chrono::steady_clock::now() - t0, 20s) << "nothing blocks (the FIFO, the devices)";
  EXPECT_TRUE(spawns().empty()) << "no refusal became a command";
  EXPECT_EQ(entities({}), (std::vector<std::string>{"body_0", "body_1"}));
}

TEST_P(SpawnablesTest, GetSpawnablesListsExactlyTheFoldersFragments) {
  const auto features =
      call<sim::GetSimulatorFeaturesResponse>("get_simulator_features", sim::GetSimulatorFeaturesRequest{});
  const std::vector<std::uint16_t>& listed = features.features.features;
  EXPECT_EQ(listed.size(), 23u);
  EXPECT_NE(std::find(listed.begin(), listed.end(), static_cast<std::uint16_t>(sim::Feature::Spawnables)),
            listed.end());

  sim::GetSpawnablesRequest req;
  req.sources = {"model://elsewhere"};
  const auto res = call<sim::GetSpawnablesResponse>("get_spawnables", req);
  ASSERT_EQ(res.result.result, SimResult::kOk) << res.result.error_message;
  // The regular *.xml files directly in the folder that parse; not the subfolder's, the links, the
  // FIFO, the device, the directory, the text file, the file too large or the one that does not parse.
  ASSERT_EQ(res.spawnables.size(), 2u);
  EXPECT_EQ(res.spawnables[0].entity_resource.uri, "ball.xml");
  EXPECT_EQ(res.spawnables[0].description, "a triangle");
  EXPECT_EQ(res.spawnables[1].entity_resource.uri, "square.xml");
  EXPECT_EQ(res.spawnables[1].description, "a square");
  EXPECT_TRUE(res.spawnables[0].entity_resource.resource_string.empty());
  // Each one's hull box about its centre of mass, as get_entity_bounds gives a body's.
  const sim::Bounds& triangle = res.spawnables[0].spawn_bounds;
  EXPECT_EQ(triangle.type, static_cast<std::uint8_t>(sim::BoundsType::Box));
  ASSERT_EQ(triangle.points.size(), 2u);
  EXPECT_NEAR(triangle.points[0].x, 8.0 / 3.0, 1e-12);
  EXPECT_NEAR(triangle.points[0].y, 1.0, 1e-12);
  EXPECT_NEAR(triangle.points[1].x, -4.0 / 3.0, 1e-12);
  EXPECT_NEAR(triangle.points[1].y, -1.0, 1e-12);
  EXPECT_EQ(res.spawnables[1].spawn_bounds.points,
            (std::vector<sim::Vector3>{{1.0, 1.0, 0.0}, {-1.0, -1.0, 0.0}}));
  // What was left out and the sources not searched, in the message.
  for (const char* says : {"bad.xml:2: ", "huge.xml", "'model://elsewhere' not searched"})
    EXPECT_NE(res.result.error_message.find(says), std::string::npos)
        << says << ": " << res.result.error_message;

  // Each uri, given back as listed, spawns; its bounds are the spawned body's.
  ASSERT_EQ(set_state(State::Paused).result, SimResult::kOk);
  for (const sim::Spawnable& s : res.spawnables) {
    const auto spawned = spawn(by_uri("", s.entity_resource.uri));
    ASSERT_EQ(spawned.result.result, SimResult::kOk) << spawned.result.error_message;
    sim::GetEntityBoundsRequest bounds;
    bounds.entity = spawned.entity_name;
    const auto got = call<sim::GetEntityBoundsResponse>("get_entity_bounds", bounds);
    ASSERT_EQ(got.result.result, SimResult::kOk) << got.result.error_message;
    ASSERT_EQ(got.bounds.points.size(), 2u);
    for (std::size_t k = 0; k < 2; ++k) {
      EXPECT_NEAR(got.bounds.points[k].x, s.spawn_bounds.points[k].x, 1e-12);
      EXPECT_NEAR(got.bounds.points[k].y, s.spawn_bounds.points[k].y, 1e-12);
    }
  }
}

TEST_P(SpawnablesTest, SpawnEntitiesAppliesEveryEntityAtOneStepBoundary) {
  ASSERT_EQ(set_state(State::Playing).result, SimResult::kOk);
  using Codes = sim::SpawnResult;
  sim::SpawnEntitiesRequest req;
  req.spawn_requests = {entity("one", "ball.xml", "", -4.0), entity("two", "square.xml", "", 4.0),
                        entity("three", "", kSquare, 8.0), entity("9bad", "", kSquare, 0.0),
                        entity("one", "square.xml", "", 0.0)};
  const auto res = call<sim::SpawnEntitiesResponse>("spawn_entities", req);
  EXPECT_EQ(res.result.result, sim::SpawnEntitiesResponse::kEntitiesSpawnFailed) << res.result.error_message;
  EXPECT_NE(res.result.error_message.find("2 of 5 spawns failed"), std::string::npos)
      << res.result.error_message;
  ASSERT_EQ(res.results.size(), 5u);
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(res.results[k].result.result, SimResult::kOk)
        << k << ": " << res.results[k].result.error_message;
    EXPECT_EQ(res.results[k].entity_name, req.spawn_requests[k].name);
  }
  EXPECT_EQ(res.results[3].result.result, Codes::kNameInvalid);
  EXPECT_EQ(res.results[4].result.result, Codes::kNameNotUnique) << res.results[4].result.error_message;
  EXPECT_TRUE(res.results[4].entity_name.empty());
  // The four that became commands (the name taken refused as it applied) applied at one step
  // boundary while the world played on.
  std::vector<msgs::CommandMessage> recorded = spawns();
  ASSERT_EQ(recorded.size(), 4u);
  for (const msgs::CommandMessage& m : recorded) EXPECT_EQ(m.step, recorded[0].step);
  EXPECT_EQ(std::count_if(recorded.begin(), recorded.end(), [](const auto& m) { return m.success; }), 3);

  // All of them well: RESULT_OK, one boundary again.
  req.spawn_requests = {entity("a", "ball.xml", "", -4.0), entity("b", "ball.xml", "", 4.0),
                        entity("c", "sub/inner.xml", "", 8.0)};
  const auto all = call<sim::SpawnEntitiesResponse>("spawn_entities", req);
  EXPECT_EQ(all.result.result, SimResult::kOk) << all.result.error_message;
  ASSERT_EQ(all.results.size(), 3u);
  recorded = spawns();
  ASSERT_EQ(recorded.size(), 7u);
  EXPECT_EQ(recorded[4].step, recorded[6].step);
  EXPECT_EQ(recorded[5].step, recorded[6].step);
  EXPECT_GT(recorded[4].step, recorded[0].step) << "the world played on between the calls";
  ASSERT_EQ(set_state(State::Paused).result, SimResult::kOk);
  EXPECT_EQ(entities({}),
            (std::vector<std::string>{"body_0", "body_1", "one", "two", "three", "a", "b", "c"}));
  // Nothing to spawn is nothing done.
  EXPECT_EQ(call<sim::SpawnEntitiesResponse>("spawn_entities", sim::SpawnEntitiesRequest{}).result.result,
            SimResult::kOk);
}

TEST_P(SpawnablesTest, AnOversizedSpawnEntitiesCallIsRefusedWholeAndTheNodeGoesOn) {
  sim::SpawnEntitiesRequest many;
  many.spawn_requests.assign(10000, entity("", "", kSquare, 0.0));
  const auto t0 = std::chrono::steady_clock::now();
  const auto res = call<sim::SpawnEntitiesResponse>("spawn_entities", many);
  EXPECT_EQ(res.result.result, SimResult::kOperationFailed);
  EXPECT_NE(res.result.error_message.find("10,000 entities in one call, at most 1,000: nothing was spawned"),
            std::string::npos)
      << res.result.error_message;
  EXPECT_TRUE(res.results.empty());
  many.spawn_requests.resize(1001);
  EXPECT_EQ(call<sim::SpawnEntitiesResponse>("spawn_entities", many).result.result,
            SimResult::kOperationFailed);
  // Fragments adding up to more than 16 MiB in one call (a file of nearly 1 MiB, 20 times).
  write(folder_ / "near.xml", std::string(kSquare) + "<!--" + std::string(1000000, '-') + "-->\n");
  sim::SpawnEntitiesRequest heavy;
  heavy.spawn_requests.assign(20, entity("", "near.xml", "", 0.0));
  const auto refused = call<sim::SpawnEntitiesResponse>("spawn_entities", heavy);
  EXPECT_EQ(refused.result.result, SimResult::kOperationFailed);
  EXPECT_NE(refused.result.error_message.find("add up to more than 16,777,216 bytes"), std::string::npos)
      << refused.result.error_message;
  EXPECT_LT(std::chrono::steady_clock::now() - t0, 30s);
  // Nothing spawned; the node answers as before.
  EXPECT_TRUE(spawns().empty());
  EXPECT_EQ(entities({}), (std::vector<std::string>{"body_0", "body_1"}));
  heavy.spawn_requests.resize(2);
  const auto two = call<sim::SpawnEntitiesResponse>("spawn_entities", heavy);
  EXPECT_EQ(two.result.result, SimResult::kOk) << two.result.error_message;
  EXPECT_EQ(entities({}), (std::vector<std::string>{"body_0", "body_1", "entity_1", "entity_2"}));
}

INSTANTIATE_TEST_SUITE_P(Middleware, SpawnablesTest, ::testing::Values("dds", "memory"),
                         [](const ::testing::TestParamInfo<std::string>& p) { return p.param; });

// ---------------------------------------------------------------------------------------------
// The SimulateSteps action, as a ROS 2 action client uses it: its three services and two topics.
struct ActionClient {
  ServiceClient send_goal, cancel_goal, get_result;
  Subscription feedback, status;
};

msgs::GoalUuid goal_id(std::uint8_t k) {
  msgs::GoalUuid id{};
  id[0] = 0xab;
  id[15] = k;
  return id;
}

class SimulateStepsTest : public SimulationServicesTest {
 protected:
  using Feedback = sim::SimulateStepsFeedbackMessage;
  using GetResult = sim::SimulateStepsGetResultResponse;

  std::unique_ptr<ActionClient> action_client(Participant& p) {
    const std::string base = "/" + node_ + "/simulate_steps/_action/";
    const std::string type(sim::SimulateStepsSendGoalRequest::kAction);
    const auto client = [&](const std::string& name, const std::string& srv) {
      auto c = ServiceClient::create(p, base + name, srv);
      if (!c) throw std::runtime_error(c.error().message);
      if (Status st = c.value().wait_for_server(20.0); !st) throw std::runtime_error(st.error().message);
      return std::move(c.value());
    };
    const auto topic = [&](const std::string& name, const std::string& msg, bool latched) {
      QosSpec q;
      q.transient_local = latched;
      q.depth = latched ? 1 : 100;
      auto s = Subscription::create(p, RawTopic{base + name, msg}, q);
      if (!s) throw std::runtime_error(s.error().message);
      return std::move(s.value());
    };
    auto a = std::unique_ptr<ActionClient>(new ActionClient{
        client("send_goal", type + "_SendGoal"),
        client("cancel_goal", std::string(msgs::CancelGoalRequest::kService)),
        client("get_result", type + "_GetResult"), topic("feedback", type + "_FeedbackMessage", false),
        topic("status", std::string(msgs::GoalStatusArray::kType), true)});
    // Feedback is volatile: the reader matches the node's writer before a goal is sent (bounded).
    for (int i = 0; i < 4000 && (a->feedback.matched() < 1 || a->status.matched() < 1); ++i)
      std::this_thread::sleep_for(5ms);
    if (a->feedback.matched() < 1) throw std::runtime_error("the feedback topic did not match in 20 s");
    return a;
  }
  std::unique_ptr<ActionClient> action_client() { return action_client(*client_); }

  template <class Res>
  static Res call_with(ServiceClient& client, const Bytes& body, double timeout_s = 60.0) {
    Result<Bytes> reply = client.call(body, timeout_s);
    if (!reply) throw std::runtime_error(reply.error().message);
    Res res;
    if (Status st = decode(std::span<const std::byte>(reply.value()), res); !st)
      throw std::runtime_error(st.error().message);
    return res;
  }
  static bool send_goal(ActionClient& a, const msgs::GoalUuid& id, std::uint64_t steps) {
    Bytes body;
    encode(sim::SimulateStepsSendGoalRequest{id, steps}, body);
    return call_with<msgs::SendGoalResponse>(a.send_goal, body).accepted;
  }
  static GetResult result(ActionClient& a, const msgs::GoalUuid& id) {
    Bytes body;
    encode(msgs::GetResultRequest{id}, body);
    return call_with<GetResult>(a.get_result, body);
  }
  static msgs::CancelGoalResponse cancel(ActionClient& a, const msgs::GoalInfo& which) {
    Bytes body;
    encode(msgs::CancelGoalRequest{which}, body);
    return call_with<msgs::CancelGoalResponse>(a.cancel_goal, body);
  }
  // Every feedback message that arrived since the last call.
  static std::vector<Feedback> feedback(ActionClient& a) {
    std::vector<Feedback> out;
    Received r;
    while (a.feedback.take(r)) {
      Feedback f;
      if (decode(r.cdr, f)) out.push_back(f);
    }
    return out;
  }
  // Waits (at most 20 s) until the status topic says `want` of goal `id`.
  static bool status_reaches(ActionClient& a, const msgs::GoalUuid& id, std::int8_t want) {
    Received r;
    for (int i = 0; i < 4000; ++i) {
      while (a.status.take(r)) {
        msgs::GoalStatusArray arr;
        if (!decode(r.cdr, arr)) continue;
        for (const msgs::GoalStatus& g : arr.status_list)
          if (g.goal_info.goal_id == id && g.status == want) return true;
      }
      std::this_thread::sleep_for(5ms);
    }
    return false;
  }
  std::int64_t step_now() {
    const auto res = states(named("^body_0$"));
    const std::uint64_t ns = static_cast<std::uint64_t>(res.states.at(0).stamp.sec) * 1'000'000'000u +
                             res.states.at(0).stamp.nanosec;
    return static_cast<std::int64_t>(std::llround(static_cast<double>(ns) * 1e-9 / scene_.world.dt));
  }
};

TEST_P(SimulateStepsTest, AGoalStepsFeedsBackAndSucceeds) {
  auto a = action_client();
  const msgs::GoalUuid id = goal_id(1);
  ASSERT_TRUE(send_goal(*a, id, 300)) << "paused at step 0: accepted";
  const GetResult r = result(*a, id);  // answered when the goal ends
  EXPECT_EQ(r.status, msgs::GoalStatus::kSucceeded);
  EXPECT_EQ(r.result.result, SimResult::kOk) << r.result.error_message;
  EXPECT_EQ(step_now(), 300) << "the world paused at the step the goal reached";
  EXPECT_TRUE(status_reaches(*a, id, msgs::GoalStatus::kSucceeded));
  // Feedback: completed + remaining = 300, never going back, the last one at the end.
  std::vector<Feedback> fb;
  for (int i = 0; i < 4000 && (fb.empty() || fb.back().remaining_steps != 0); ++i) {
    for (const Feedback& f : feedback(*a)) fb.push_back(f);
    if (fb.empty() || fb.back().remaining_steps != 0) std::this_thread::sleep_for(5ms);
  }
  ASSERT_FALSE(fb.empty());
  for (std::size_t k = 0; k < fb.size(); ++k) {
    EXPECT_EQ(fb[k].goal_id, id);
    EXPECT_EQ(fb[k].completed_steps + fb[k].remaining_steps, 300u);
    if (k > 0) {
      EXPECT_GE(fb[k].completed_steps, fb[k - 1].completed_steps);
    }
  }
  EXPECT_EQ(fb.back().completed_steps, 300u);
  // The result stays: a second get_result answers the same at once.
  EXPECT_EQ(result(*a, id), r);
  // The goal was a `step 300` command (recorded), and a second goal goes on from there.
  ASSERT_TRUE(send_goal(*a, goal_id(2), 5));
  EXPECT_EQ(result(*a, goal_id(2)).status, msgs::GoalStatus::kSucceeded);
  EXPECT_EQ(step_now(), 305);
  using K = control::CommandKind;
  EXPECT_EQ(applied(), (std::vector<K>{K::Step, K::Step}));
}

TEST_P(SimulateStepsTest, ACancelStopsAtTheNextBoundaryAndReSimulatesExactly) {
  // STOPPED -> PAUSED, a pause command: an offline re-run starts running, the live node paused.
  ASSERT_EQ(set_state(State::Paused).result, SimResult::kOk);
  auto a = action_client();
  const msgs::GoalUuid id = goal_id(3);
  ASSERT_TRUE(send_goal(*a, id, 100000));  // 20 s or more at 200 us a step: canceled long before
  bool moving = false;
  for (int i = 0; i < 4000 && !moving; ++i) {
    for (const Feedback& f : feedback(*a)) moving |= f.completed_steps > 1;
    if (!moving) std::this_thread::sleep_for(5ms);
  }
  ASSERT_TRUE(moving) << "no feedback of a completed step within 20 s";
  const msgs::CancelGoalResponse c = cancel(*a, msgs::GoalInfo{id, {}});
  EXPECT_EQ(c.return_code, msgs::CancelGoalResponse::kErrorNone);
  ASSERT_EQ(c.goals_canceling.size(), 1u);
  EXPECT_EQ(c.goals_canceling[0].goal_id, id);
  const GetResult r = result(*a, id);
  EXPECT_EQ(r.status, msgs::GoalStatus::kCanceled);
  EXPECT_EQ(r.result.result, SimResult::kOk);
  const std::int64_t at = step_now();
  EXPECT_GT(at, 0);
  EXPECT_LT(at, 100000);
  EXPECT_NE(r.result.error_message.find("canceled after " + std::to_string(at) +
                                        " steps of 100000, paused at step " + std::to_string(at)),
            std::string::npos)
      << r.result.error_message;
  EXPECT_EQ(state(), static_cast<std::uint8_t>(State::Paused));
  EXPECT_EQ(cancel(*a, msgs::GoalInfo{id, {}}).return_code, msgs::CancelGoalResponse::kErrorGoalTerminated);
  // The session (a step 100000, then a stop_stepping) re-simulates to the same step and states.
  const auto live = states();
  const test::Snapshot again = resimulated();
  EXPECT_EQ(again.step, at);
  expect_states_equal(live, again);
  using K = control::CommandKind;
  EXPECT_EQ(applied(), (std::vector<K>{K::Pause, K::Step, K::StopStepping}));
}

TEST_P(SimulateStepsTest, RefusedGoalsAndHostileClientsAreAnsweredNeverStalled) {
  auto a = action_client();
  EXPECT_FALSE(send_goal(*a, goal_id(10), 0)) << "0 steps";
  EXPECT_FALSE(send_goal(*a, goal_id(11), std::uint64_t{1} << 63)) << "past int64";
  ASSERT_EQ(set_state(State::Playing).result, SimResult::kOk);
  EXPECT_FALSE(send_goal(*a, goal_id(12), 10)) << "not paused";
  ASSERT_EQ(set_state(State::Paused).result, SimResult::kOk);

  // Unknown goals: a cancel says so, a result is answered at once with status UNKNOWN.
  EXPECT_EQ(cancel(*a, msgs::GoalInfo{goal_id(13), {}}).return_code,
            msgs::CancelGoalResponse::kErrorUnknownGoalId);
  EXPECT_EQ(result(*a, goal_id(13)).status, msgs::GoalStatus::kUnknown);
  EXPECT_EQ(cancel(*a, msgs::GoalInfo{}).return_code, msgs::CancelGoalResponse::kErrorRejected)
      << "nothing to cancel";

  // Malformed requests get no reply; the server goes on.
  const Bytes garbage{std::byte{0}, std::byte{1}, std::byte{0}, std::byte{0}, std::byte{0xff}};
  ASSERT_TRUE(a->send_goal.send(garbage).ok());
  ASSERT_TRUE(a->get_result.send(garbage).ok());
  ASSERT_TRUE(a->cancel_goal.send(garbage).ok());

  // One goal at a time: a second goal, and the same id again, are refused while it runs.
  const msgs::GoalUuid running = goal_id(14);
  ASSERT_TRUE(send_goal(*a, running, 100000));
  EXPECT_FALSE(send_goal(*a, goal_id(15), 10));
  EXPECT_FALSE(send_goal(*a, running, 10));

  // A flood of goals from one client, without waiting: each is refused or dropped (counted), none
  // is accepted, and the server answers again at once.
  Bytes body;
  for (std::uint8_t k = 0; k < 200; ++k) {
    encode(sim::SimulateStepsSendGoalRequest{goal_id(static_cast<std::uint8_t>(k + 50)), 10}, body);
    ASSERT_TRUE(a->send_goal.send(body).ok());
  }
  std::size_t replies = 0;
  RequestHeader h;
  Bytes reply;
  // Until every request is answered, or none came for a second (the rest were dropped).
  for (int i = 0; i < 400 && replies < 200 && a->send_goal.wait_reply(1.0); ++i) {
    while (a->send_goal.take_reply(h, reply)) {
      msgs::SendGoalResponse res;
      ASSERT_TRUE(decode(std::span<const std::byte>(reply), res).ok());
      EXPECT_FALSE(res.accepted);
      ++replies;
    }
  }
  EXPECT_GT(replies, 0u);

  // A client that vanished with a get_result waiting: the goal goes on; a cancel of every goal
  // (zero id and stamp) from another client ends it CANCELED, and a new client reads the result.
  {
    auto gone = action_client();
    Bytes ask;
    encode(msgs::GetResultRequest{running}, ask);
    ASSERT_TRUE(gone->get_result.send(ask).ok());
  }
  const msgs::CancelGoalResponse all = cancel(*a, msgs::GoalInfo{});
  EXPECT_EQ(all.return_code, msgs::CancelGoalResponse::kErrorNone);
  ASSERT_EQ(all.goals_canceling.size(), 1u);
  auto later = action_client();
  EXPECT_EQ(result(*later, running).status, msgs::GoalStatus::kCanceled);
  // Every request is accounted for in the node's counters: answered, or dropped and counted.
  const NodeServiceCounters n = services_->counters();
  EXPECT_GE(n.received, n.calls);
  EXPECT_GE(n.dropped, 3u) << "the three malformed requests";
  ASSERT_TRUE(send_goal(*later, goal_id(16), 3)) << "the server takes goals again";
  EXPECT_EQ(result(*later, goal_id(16)).status, msgs::GoalStatus::kSucceeded);
}

INSTANTIATE_TEST_SUITE_P(Middleware, SimulateStepsTest, ::testing::Values("dds", "memory"),
                         [](const ::testing::TestParamInfo<std::string>& p) { return p.param; });

// ---------------------------------------------------------------------------------------------
// Worlds: load_world (a uri of the node's worlds folder, or a scene's text), unload_world,
// get_current_world and get_available_worlds; every code of LoadWorld.srv and UnloadWorld.srv; the
// session re-simulated from its commands, which carry the scenes' texts.

void write_file(const std::filesystem::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  if (!out) throw std::runtime_error("cannot write " + path.string());
}

// A world of one body, its own dt and integrator, long enough for any test.
const std::string kWorldScene = test::square_world_text("1000.0");

class WorldsTest : public SimulationServicesTest {
 protected:
  void SetUp() override {
    namespace fs = std::filesystem;
    root_ = fs::path(::testing::TempDir()) / test::node_name("rbsim_worlds");
    folder_ = root_ / "worlds";
    fs::remove_all(root_);
    fs::create_directories(folder_);
    write_file(folder_ / "square.xml", kWorldScene);
    write_file(folder_ / "control.xml", test::control_scene_text());
    write_file(folder_ / "odd.xml", std::string(kWorldScene).replace(8, 0, "<gadget/>\n"));
    write_file(folder_ / "bad.xml", "<scene>\n<rigidbodyvertex x=\"0\"/>\n</scene>\n");
    write_file(folder_ / "notes.txt", "not a world");
    write_file(root_ / "outside.xml", kWorldScene);
    fs::create_symlink(root_ / "outside.xml", folder_ / "link.xml");
    SimulationServicesTest::SetUp();
  }
  void TearDown() override {
    SimulationServicesTest::TearDown();
    std::error_code ec;
    std::filesystem::remove_all(root_, ec);
  }
  void configure(NodeServicesOptions& options) override { options.worlds = {folder_.string()}; }

  sim::LoadWorldResponse load(std::string uri, std::string text = {}, bool strict = false) {
    sim::LoadWorldRequest req;
    req.world_resource.uri = std::move(uri);
    req.world_resource.resource_string = std::move(text);
    req.fail_on_unsupported_element = strict;
    return call<sim::LoadWorldResponse>("load_world", req);
  }
  sim::GetCurrentWorldResponse current() {
    return call<sim::GetCurrentWorldResponse>("get_current_world", sim::GetCurrentWorldRequest{});
  }

  std::filesystem::path root_, folder_;
};

TEST_P(WorldsTest, ALoadedWorldIsStoppedAtStepZeroAndReSimulatesExactly) {
  ASSERT_EQ(set_state(State::Paused).result, SimResult::kOk);
  ASSERT_EQ(step(10).result, SimResult::kOk);
  EXPECT_EQ(current().world.name, "control");
  const auto loaded = load("square.xml");
  ASSERT_EQ(loaded.result.result, SimResult::kOk) << loaded.result.error_message;
  EXPECT_EQ(loaded.world.name, "square");
  EXPECT_EQ(loaded.world.world_resource.uri, "square.xml");
  EXPECT_EQ(loaded.world.description, "a falling square");
  EXPECT_EQ(state(), static_cast<std::uint8_t>(State::Stopped));
  EXPECT_EQ(entities({}), std::vector<std::string>{"body_0"});
  const auto now = current();
  ASSERT_EQ(now.result.result, SimResult::kOk) << now.result.error_message;
  EXPECT_EQ(now.world, loaded.world);
  // Played from its step 0 as the scene alone would be.
  ASSERT_EQ(step(25).result, SimResult::kOk);
  const auto live = states();
  ASSERT_EQ(live.states.size(), 1u);
  const World alone = stepped(test::scene_from(kWorldScene), 25);
  EXPECT_EQ(live.states[0].position.x, alone.x()[0]);
  EXPECT_EQ(live.states[0].linear_velocity.y, alone.vy()[0]);
  // Back to the first world, as text; the session's commands re-run with no file.
  const auto back = load("", test::control_scene_text());
  ASSERT_EQ(back.result.result, SimResult::kOk) << back.result.error_message;
  EXPECT_EQ(back.world.world_resource.uri, "");
  ASSERT_EQ(step(7).result, SimResult::kOk);
  const auto again = states();
  ASSERT_EQ(again.states.size(), 2u);
  std::filesystem::remove_all(folder_);
  const test::Snapshot rerun = resimulated();
  ASSERT_EQ(rerun.step, 7);
  expect_states_equal(again, rerun);
}

TEST_P(WorldsTest, EveryLoadWorldCodeIsReachedAndTheRunningWorldStaysUntouched) {
  using Res = sim::LoadWorldResponse;
  const auto code = [](const Res& r) { return r.result.result; };
  EXPECT_EQ(code(load("", "")), Res::kNoResource);
  EXPECT_EQ(code(load("missing.xml", kWorldScene)), Res::kNoResource) << "the text is ignored beside a uri";
  EXPECT_EQ(code(load("missing.xml")), Res::kNoResource);
  EXPECT_EQ(code(load("../outside.xml")), Res::kNoResource);
  EXPECT_EQ(code(load((root_ / "outside.xml").string())), Res::kNoResource);
  const auto link = load("link.xml");
  EXPECT_EQ(code(link), Res::kNoResource);
  EXPECT_NE(link.result.error_message.find("symbolic link"), std::string::npos) << link.result.error_message;
  EXPECT_EQ(code(load("notes.txt")), Res::kUnsupportedFormat);
  EXPECT_EQ(code(load("/dev/null.xml")), Res::kNoResource);
  const auto bad = load("bad.xml");
  EXPECT_EQ(code(bad), Res::kResourceParseError);
  EXPECT_NE(bad.result.error_message.find("bad.xml:2:"), std::string::npos) << bad.result.error_message;
  const auto bad_text = load("", "<scene><rigidbody p=\"0\"/></scene>");
  EXPECT_EQ(code(bad_text), Res::kResourceParseError);
  EXPECT_NE(bad_text.result.error_message.find("resource_string:1:"), std::string::npos)
      << bad_text.result.error_message;
  const auto odd = load("odd.xml", "", /*strict=*/true);
  EXPECT_EQ(code(odd), Res::kUnsupportedElements);
  EXPECT_NE(odd.result.error_message.find("gadget"), std::string::npos) << odd.result.error_message;
  const auto huge = load("", std::string((64u << 20) + 1, ' '));  // past the 64 MiB a world may have
  EXPECT_EQ(code(huge), Res::kResourceParseError);
  // None of it touched the world, nor was any of it a command.
  EXPECT_EQ(current().world.name, "control");
  EXPECT_EQ(entities({}), (std::vector<std::string>{"body_0", "body_1"}));
  EXPECT_TRUE(applied().empty());
  // Unknown elements ignored when not asked to fail on them, as the scene loader does.
  EXPECT_EQ(code(load("odd.xml")), SimResult::kOk);
}

TEST_P(WorldsTest, UnloadLeavesNoWorldUntilALoad) {
  using UnloadRes = sim::UnloadWorldResponse;
  ASSERT_EQ(call<UnloadRes>("unload_world", sim::UnloadWorldRequest{}).result.result, SimResult::kOk);
  EXPECT_EQ(state(), static_cast<std::uint8_t>(State::NoWorld));
  EXPECT_EQ(current().result.result, sim::GetCurrentWorldResponse::kNoWorldLoaded);
  EXPECT_EQ(call<UnloadRes>("unload_world", sim::UnloadWorldRequest{}).result.result,
            UnloadRes::kNoWorldLoaded);
  EXPECT_EQ(set_state(State::Playing).result, SetRes::kStateTransitionError);
  EXPECT_EQ(step(1).result, SimResult::kOperationFailed);
  EXPECT_TRUE(entities({}).empty());
  EXPECT_EQ(set_state(State::NoWorld).result, SetRes::kIncorrectTransition);
  ASSERT_EQ(load("square.xml").result.result, SimResult::kOk);
  EXPECT_EQ(state(), static_cast<std::uint8_t>(State::Stopped));
  ASSERT_EQ(set_state(State::Playing).result, SimResult::kOk);
}

TEST_P(WorldsTest, GetAvailableWorldsListsTheFoldersScenes) {
  const auto all =
      call<sim::GetAvailableWorldsResponse>("get_available_worlds", sim::GetAvailableWorldsRequest{});
  ASSERT_EQ(all.result.result, SimResult::kOk) << all.result.error_message;
  std::vector<std::string> names;
  for (const sim::WorldResource& w : all.worlds) names.push_back(w.name + "=" + w.world_resource.uri);
  EXPECT_EQ(names, (std::vector<std::string>{"control=control.xml", "odd=odd.xml", "square=square.xml"}));
  EXPECT_EQ(all.worlds[2].description, "a falling square");
  EXPECT_NE(all.result.error_message.find("left out bad.xml:2:"), std::string::npos)
      << all.result.error_message;
  sim::GetAvailableWorldsRequest tagged;
  tagged.filter.tags = {"outdoor"};
  EXPECT_EQ(call<sim::GetAvailableWorldsResponse>("get_available_worlds", tagged).result.result,
            SimResult::kFeatureUnsupported);
  const auto features =
      call<sim::GetSimulatorFeaturesResponse>("get_simulator_features", sim::GetSimulatorFeaturesRequest{});
  const auto& listed = features.features.features;
  EXPECT_NE(
      std::find(listed.begin(), listed.end(), static_cast<std::uint16_t>(sim::Feature::AvailableWorlds)),
      listed.end());
}

INSTANTIATE_TEST_SUITE_P(Middleware, WorldsTest, ::testing::Values("dds", "memory"),
                         [](const ::testing::TestParamInfo<std::string>& p) { return p.param; });

}  // namespace
}  // namespace rbsim::node
