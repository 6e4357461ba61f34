// The SimulateSteps action against its peer, the run loop alone (what `rbsim run` does), in one
// run: a node of this process (its Controller and NodeServices over Cyclone DDS on loopback, the
// run loop on another thread, paused, as fast as possible) is sent a goal of N steps by an action
// client of another participant, timed from the goal request to the result; beside it, a Driver
// steps a fresh world of the same scene N steps with no sink. Rounds alternate, so both see the
// same machine.
//
//   rbsim_bench_simulate_steps SCENE [--steps N] [--rounds R] [--domain D]
//
// The target (issue 37): the action's steps per second within 1.1x of the run's (ratio <= 1.1).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <future>
#include <string>
#include <thread>
#include <vector>

#include "rbsim/dds.hpp"
#include "rbsim/interfaces.hpp"
#include "rbsim/node_services.hpp"
#include "rbsim/run.hpp"
#include "rbsim/scene.hpp"
#include "rbsim/service.hpp"
#include "rbsim/simulation_interfaces.hpp"

namespace {

using namespace rbsim;
using Clock = std::chrono::steady_clock;
namespace sim = msgs::simulation;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

int fail(const std::string& what) {
  std::fprintf(stderr, "rbsim_bench_simulate_steps: %s\n", what.c_str());
  return 1;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || std::strcmp(argv[1], "--help") == 0) {
    std::printf("usage: rbsim_bench_simulate_steps SCENE [--steps N] [--rounds R] [--domain D]\n");
    return argc < 2 ? 2 : 0;
  }
  const std::string path = argv[1];
  std::int64_t steps = 10000;
  int rounds = 3;
  std::uint32_t domain = 173;
  for (int i = 2; i + 1 < argc; i += 2) {
    const std::string flag = argv[i];
    if (flag == "--steps")
      steps = std::atoll(argv[i + 1]);
    else if (flag == "--rounds")
      rounds = std::atoi(argv[i + 1]);
    else if (flag == "--domain")
      domain = static_cast<std::uint32_t>(std::atoi(argv[i + 1]));
    else
      return fail("unknown option " + flag);
  }
  Result<Scene> scene = load_scene(path);
  if (!scene) return fail(scene.error().message);

  // The node: paused, as fast as possible, long enough for every round's goal.
  const std::int64_t run_steps = steps * (rounds + 1);
  control::Controller controller(scene.value(), run_steps, control::RunSettings{0.0, 1, true});
  auto server = node::create_dds_participant(domain, node::NodeName{"/", "bench_sim"});
  if (!server) return fail(server.error().message);
  node::NodeServicesOptions options;
  options.node = "/bench_sim";
  auto services = node::NodeServices::create(server.value(), controller, options);
  if (!services) return fail(services.error().message);
  Result<Driver> node_driver = Driver::create(scene.value());
  if (!node_driver) return fail(node_driver.error().message);
  std::future<Status> loop = std::async(std::launch::async, [&] {
    DriverOptions o;
    o.steps = run_steps;
    o.control = &controller;
    return node_driver.value().run_pass(o);
  });

  auto client = node::create_dds_participant(domain, node::NodeName{"/", "bench_sim_client"});
  if (!client) return fail(client.error().message);
  const std::string base = "/bench_sim/simulate_steps/_action/";
  const std::string type(sim::SimulateStepsSendGoalRequest::kAction);
  auto send_goal = node::ServiceClient::create(client.value(), base + "send_goal", type + "_SendGoal");
  auto get_result = node::ServiceClient::create(client.value(), base + "get_result", type + "_GetResult");
  if (!send_goal || !get_result) return fail("cannot create the action client");
  if (!send_goal.value().wait_for_server(20.0) || !get_result.value().wait_for_server(20.0))
    return fail("the action server did not match in 20 s");

  std::printf("scene %s, %lld steps per round, %d rounds (interleaved)\n", path.c_str(),
              static_cast<long long>(steps), rounds);
  std::printf("%-6s %14s %14s %8s\n", "round", "run steps/s", "action steps/s", "ratio");
  std::vector<double> ratios;
  for (int r = 0; r < rounds; ++r) {
    // The peer: the run loop alone, a fresh world, no sink (rbsim run SCENE --steps N).
    Result<Driver> offline = Driver::create(scene.value());
    if (!offline) return fail(offline.error().message);
    DriverOptions o;
    o.steps = steps;
    const auto t0 = Clock::now();
    if (Status st = offline.value().run_pass(o); !st) return fail(st.error().message);
    const double run_s = seconds_since(t0);

    // The action: goal request to result.
    msgs::GoalUuid id{};
    id[0] = static_cast<std::uint8_t>(r + 1);
    Bytes goal, ask;
    msgs::simulation::encode(sim::SimulateStepsSendGoalRequest{id, static_cast<std::uint64_t>(steps)}, goal);
    msgs::encode(msgs::GetResultRequest{id}, ask);
    const auto t1 = Clock::now();
    Result<Bytes> accepted = send_goal.value().call(goal, 20.0);
    if (!accepted) return fail("send_goal: " + accepted.error().message);
    msgs::SendGoalResponse sg;
    if (!msgs::decode(std::span<const std::byte>(accepted.value()), sg) || !sg.accepted)
      return fail("the goal was not accepted");
    Result<Bytes> result = get_result.value().call(ask, 600.0);
    const double action_s = seconds_since(t1);
    if (!result) return fail("get_result: " + result.error().message);
    sim::SimulateStepsGetResultResponse res;
    if (!msgs::simulation::decode(std::span<const std::byte>(result.value()), res) ||
        res.status != msgs::GoalStatus::kSucceeded)
      return fail("the goal did not succeed: " + res.result.error_message);
    const double n = static_cast<double>(steps);
    ratios.push_back(action_s / run_s);
    std::printf("%-6d %14.0f %14.0f %8.3f\n", r + 1, n / run_s, n / action_s, action_s / run_s);
  }
  std::sort(ratios.begin(), ratios.end());
  std::printf("median ratio (action time / run time): %.3f (target <= 1.1)\n", ratios[ratios.size() / 2]);
  controller.close("the benchmark ended");
  if (Status st = loop.get(); !st) return fail(st.error().message);
  return 0;
}
