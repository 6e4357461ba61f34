// RemoteSteering (rbsim/remote_steering.hpp), what rbsim bridge steers a node with: a node of this process
// (a Controller and its NodeServices, run by the control tests' loop on another thread) steered
// through its ROS 2 services, over the loopback DDS configuration and over the in-memory
// middleware (the same seam), and what it refuses.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <future>
#include <mutex>
#include <string>
#include <thread>

#include "control_test_util.hpp"
#include "rbsim/dds.hpp"
#include "rbsim/memory_middleware.hpp"
#include "rbsim/node_services.hpp"
#include "rbsim/remote_steering.hpp"

namespace rbsim::bridge {

using namespace node;
namespace {

using namespace std::chrono_literals;
using control::Command;
using control::CommandKind;
using control::CommandResult;
using V = msgs::ParameterValue;

constexpr std::uint32_t kDomain = 157;  // its own: service_test has 156

// The result of `command` submitted to `steering`, within 20 s.
CommandResult submit(control::Steering& steering, Command command) {
  auto promise = std::make_shared<std::promise<CommandResult>>();
  std::future<CommandResult> f = promise->get_future();
  steering.submit(std::move(command), [promise](const CommandResult& r) { promise->set_value(r); });
  if (f.wait_for(20s) != std::future_status::ready) throw std::runtime_error("no result within 20 s");
  return f.get();
}

Command kind(CommandKind k, std::int64_t steps = 0) {
  Command c;
  c.kind = k;
  c.steps = steps;
  return c;
}

// Runs on both middlewares behind the seam: over DDS (the loopback configuration) and in memory.
class RemoteSteeringSeam : public ::testing::TestWithParam<std::string> {
 protected:
  Participant participant(const std::string& name) {
    const NodeName node{"/", name};
    auto p = GetParam() == "memory" ? create_memory_participant(network_, node)
                                    : create_dds_participant(kDomain, node);
    if (!p) throw std::runtime_error(p.error().message);
    return std::move(p.value());
  }
  std::shared_ptr<MemoryNetwork> network_ = std::make_shared<MemoryNetwork>();
};

TEST_P(RemoteSteeringSeam, RelaysParametersAndControlsToTheNodesServices) {
  const Scene scene = test::control_scene();
  control::Controller controller(scene, 120, control::RunSettings{0.0, 1, true});  // paused at step 0
  const std::string node = "remote_steering_" + std::to_string(::getpid());
  Participant node_participant = participant(node);
  auto services = NodeServices::create(node_participant, controller, {"/" + node, scene.world.dt});
  ASSERT_TRUE(services.ok()) << services.error().message;
  controller.on_command(
      [&s = *services.value()](const Command& c, const CommandResult& r) { s.command_applied(c, r); });
  auto run = std::async(std::launch::async, [&] { return test::run(scene, 120, &controller); });

  // Before the steering: its thread may call the observer until the steering is destroyed.
  std::mutex mu;
  std::vector<msgs::Parameter> updates;
  Participant bridge = participant("remote_steering_bridge");
  auto steering = RemoteSteering::create(bridge, {"/" + node});
  ASSERT_TRUE(steering.ok()) << steering.error().message;
  RemoteSteering& remote = *steering.value();
  remote.on_command([&](const Command&, const CommandResult& r) {
    const std::lock_guard lock(mu);
    updates.insert(updates.end(), r.changed.begin(), r.changed.end());
  });
  ASSERT_TRUE(remote.refresh().ok());
  EXPECT_EQ(remote.names(), controller.names());
  EXPECT_EQ(remote.get({"forces.1.fx", "nosuch"}), controller.get({"forces.1.fx", "nosuch"}));
  EXPECT_EQ(remote.types({"forces.1.pointsperedge"}), std::vector{msgs::ParameterType::Integer});

  // set_parameters: each its own result; the node's parameter event reaches observers and table.
  Command set = kind(CommandKind::SetParameters);
  set.atomic = false;
  set.parameters = {{"forces.1.fx", V::of_double(-2.0)}, {"nosuch", V::of_double(1.0)}};
  const CommandResult r = submit(remote, set);
  ASSERT_EQ(r.results.size(), 2u) << r.message;
  EXPECT_TRUE(r.results[0].successful);
  EXPECT_FALSE(r.results[1].successful);
  EXPECT_FALSE(r.successful);
  EXPECT_EQ(r.changed, (std::vector<msgs::Parameter>{{"forces.1.fx", V::of_double(-2.0)}}));
  EXPECT_EQ(controller.get({"forces.1.fx"})[0], V::of_double(-2.0));
  bool seen = false;
  for (int i = 0; i < 500 && !seen; ++i) {
    {
      const std::lock_guard lock(mu);
      for (const msgs::Parameter& p : updates)
        seen = seen || (p.name == "forces.1.fx" && p.value == V::of_double(-2.0));
    }
    if (!seen) std::this_thread::sleep_for(10ms);
  }
  EXPECT_TRUE(seen) << "the node's /parameter_events reach the observers";
  EXPECT_EQ(remote.get({"forces.1.fx"})[0], V::of_double(-2.0));

  // An atomic batch with an unknown name changes nothing.
  set.atomic = true;
  set.parameters = {{"forces.1.fy", V::of_double(4.0)}, {"nosuch", V::of_double(1.0)}};
  const CommandResult atomic = submit(remote, set);
  EXPECT_FALSE(atomic.successful);
  EXPECT_TRUE(atomic.changed.empty());
  EXPECT_EQ(controller.get({"forces.1.fy"})[0], V::of_double(0.5));

  // Controls: step while paused (the reply names the step it ends at), an impulse, then resume
  // ends the run. The run is still paused at step 0 (the parameter sets above stepped nothing), so
  // `step 3` applies at the boundary of step 0 and ends at step 3.
  const CommandResult stepped = submit(remote, kind(CommandKind::Step, 3));
  EXPECT_TRUE(stepped.successful) << stepped.message;
  EXPECT_EQ(stepped.ends_at, 3);
  Command impulse = kind(CommandKind::Impulse);
  impulse.impulse.body = 99;
  const CommandResult refused = submit(remote, impulse);
  EXPECT_FALSE(refused.successful);
  EXPECT_NE(refused.message.find("body"), std::string::npos) << refused.message;
  const CommandResult resumed = submit(remote, kind(CommandKind::Resume));
  EXPECT_TRUE(resumed.successful) << resumed.message;
  ASSERT_EQ(run.wait_for(60s), std::future_status::ready);
  EXPECT_EQ(run.get().back().step, 120);
  EXPECT_EQ(remote.calls(), 5u);
}

TEST_P(RemoteSteeringSeam, RefusesWhatAServiceCannotSayAndANodeThatIsNotThere) {
  Participant bridge = participant("remote_steering_alone");
  RemoteSteeringOptions o;
  o.node = "/nobody_" + std::to_string(::getpid());
  o.match_timeout_s = 0.3;
  auto steering = RemoteSteering::create(bridge, o);
  ASSERT_TRUE(steering.ok()) << steering.error().message;
  RemoteSteering& remote = *steering.value();

  Command at_step = kind(CommandKind::Pause);
  at_step.step = 5;
  EXPECT_NE(submit(remote, at_step).message.find("for a given step"), std::string::npos);
  Command timed = kind(CommandKind::Pause);
  timed.pause_seconds = 0.5;
  EXPECT_NE(submit(remote, timed).message.find("timed pause"), std::string::npos);
  EXPECT_NE(submit(remote, kind(CommandKind::Step, 0)).message.find("steps"), std::string::npos);

  const CommandResult absent = submit(remote, kind(CommandKind::Resume));
  EXPECT_FALSE(absent.successful);
  EXPECT_NE(absent.message.find(o.node + " does not serve std_srvs/srv/Trigger"), std::string::npos)
      << absent.message;
  const Status table = remote.refresh();
  ASSERT_FALSE(table.ok());
  EXPECT_NE(table.error().message.find(o.node), std::string::npos) << table.error().message;
  EXPECT_TRUE(remote.names().empty());
}

INSTANTIATE_TEST_SUITE_P(Middleware, RemoteSteeringSeam, ::testing::Values("dds", "memory"),
                         [](const ::testing::TestParamInfo<std::string>& p) { return p.param; });

}  // namespace
}  // namespace rbsim::bridge
