// simulation_interfaces' services on the node (node/sim/src/simulation_services.*), called as a
// ROS 2 client calls them: a node of this process (a Controller and its NodeServices, the control
// tests' run loop on another thread), over the loopback DDS configuration and over the in-memory
// middleware. The states are checked against a World stepped here, the codes against the
// definitions' constants.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <future>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "control_test_util.hpp"
#include "rbsim/command_script.hpp"
#include "rbsim/dds.hpp"
#include "rbsim/memory_middleware.hpp"
#include "rbsim/node_services.hpp"
#include "rbsim/service_event.hpp"
#include "rbsim/simulation_interfaces.hpp"

namespace rbsim::node {
namespace {

using namespace std::chrono_literals;
namespace sim = msgs::simulation;
using SimResult = sim::Result;
using State = sim::State;
using SetRes = sim::SetSimulationStateResponse;

constexpr std::uint32_t kDomain = 159;    // its own: test/dds has 143..157, test/middleware 158
constexpr std::int64_t kSteps = 1000000;  // never reached: each test ends the run itself

std::string node_name() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  std::string test = info->name();
  for (char& c : test) c = (c == '/') ? '_' : c;
  return "sim_services_" + std::to_string(::getpid()) + "_" + test;
}

// A node of this process: paused at step 0 (STOPPED), the run loop on another thread at real
// time, and a client participant.
class SimulationServicesTest : public ::testing::TestWithParam<std::string> {
 protected:
  void SetUp() override {
    node_ = node_name();
    server_.emplace(participant(node_));
    auto services = NodeServices::create(*server_, controller_, {"/" + node_, scene_.world.dt});
    ASSERT_TRUE(services.ok()) << services.error().message;
    services_ = std::move(services.value());
    controller_.on_command([this](const control::Command& c, const control::CommandResult& r) {
      services_->command_applied(c, r);
      const std::lock_guard lock(mu_);
      applied_.push_back(c.kind);
      recorded_.push_back(control::to_message(c, r, recorded_.size(), scene_.world.dt));
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

  Participant participant(const std::string& name) {
    const NodeName n{"/", name};
    auto p =
        GetParam() == "memory" ? create_memory_participant(network_, n) : create_dds_participant(kDomain, n);
    if (!p) throw std::runtime_error(p.error().message);
    return std::move(p.value());
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
    DriverOptions options;
    options.steps = kSteps;
    options.control = &controller_;
    options.pace = [](const World&) { std::this_thread::sleep_for(200us); };
    return driver.value().run_pass(options);
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

  const Scene scene_ = test::control_scene();
  control::Controller controller_{scene_, kSteps, control::RunSettings{1.0, 1, true}};
  std::shared_ptr<MemoryNetwork> network_ = std::make_shared<MemoryNetwork>();
  std::string node_;
  std::optional<Participant> server_, client_;
  std::unique_ptr<NodeServices> services_;
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
  for (const sim::Feature f :
       {sim::Feature::EntityBounds, sim::Feature::EntityBoundsBox, sim::Feature::EntityCategories,
        sim::Feature::EntityStateGetting, sim::Feature::EntityStateSetting, sim::Feature::EntityInfoGetting,
        sim::Feature::SimulationReset, sim::Feature::SimulationStateGetting,
        sim::Feature::SimulationStateSetting, sim::Feature::SimulationStatePause,
        sim::Feature::StepSimulationSingle, sim::Feature::StepSimulationMultiple}) {
    EXPECT_TRUE(has(f)) << static_cast<int>(f);
  }
  EXPECT_EQ(listed.size(), 12u);

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
  EXPECT_FALSE(has(sim::Feature::SimulationResetSpawned));
  for (const std::uint8_t scope :
       {sim::ResetSimulationRequest::kScopeTime, sim::ResetSimulationRequest::kScopeState,
        sim::ResetSimulationRequest::kScopeSpawned}) {
    sim::ResetSimulationRequest reset;
    reset.scope = scope;
    EXPECT_EQ(call<sim::ResetSimulationResponse>("reset_simulation", reset).result.result,
              SimResult::kFeatureUnsupported)
        << "scope " << int(scope);
  }
  EXPECT_EQ(set_state(State::Quitting).result, SimResult::kFeatureUnsupported);
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
  std::vector<control::ScriptedCommand> script;
  {
    const std::lock_guard lock(mu_);
    for (std::size_t k = 0; k < recorded_.size(); ++k) {
      Result<control::Command> back = control::from_message(recorded_[k]);
      ASSERT_TRUE(back.ok()) << back.error().message;
      script.push_back({back.value(), recorded_[k].success, "command " + std::to_string(k)});
    }
  }
  const auto resimulate = [&](bool with_set) {
    std::vector<control::ScriptedCommand> commands;
    for (const control::ScriptedCommand& c : script) {
      if (with_set || c.command.kind != control::CommandKind::SetState) commands.push_back(c);
    }
    control::ScriptedRun run(scene_, kSteps, std::move(commands));
    std::vector<test::Snapshot> snaps = test::run(scene_, kSteps, &run.controller());
    EXPECT_TRUE(run.finish("session").ok()) << (run.mismatches().empty() ? "" : run.mismatches()[0]);
    return snaps.back();
  };
  const test::Snapshot again = resimulate(true);
  ASSERT_EQ(again.step, 30);
  const std::size_t n = 2;  // the snapshot's columns: x, y, theta, vx, vy, omega of every body
  for (std::size_t b = 0; b < n; ++b) {
    EXPECT_EQ(live.states[b].position.x, again.state[0 * n + b]);
    EXPECT_EQ(live.states[b].position.y, again.state[1 * n + b]);
    EXPECT_EQ(live.states[b].orientation.z, msgs::quaternion_z(again.state[2 * n + b]).z);
    EXPECT_EQ(live.states[b].linear_velocity.x, again.state[3 * n + b]);
    EXPECT_EQ(live.states[b].linear_velocity.y, again.state[4 * n + b]);
    EXPECT_EQ(live.states[b].angular_velocity.z, again.state[5 * n + b]);
  }
  EXPECT_NE(resimulate(false).state, again.state) << "without the set, the run differs";
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

INSTANTIATE_TEST_SUITE_P(Middleware, SimulationServicesTest, ::testing::Values("dds", "memory"),
                         [](const ::testing::TestParamInfo<std::string>& p) { return p.param; });

}  // namespace
}  // namespace rbsim::node
