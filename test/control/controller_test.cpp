// The Controller (rbsim/control.hpp) on the Driver's one run loop: commands applied at step
// boundaries give exactly the runs of scenes edited the same way; pauses change wall time only;
// reset reproduces the run from step 0; commands from other threads apply at boundaries.
#include "rbsim/control.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <future>
#include <optional>
#include <string>
#include <thread>

#include "control_test_util.hpp"

namespace rbsim::control {
namespace {

using namespace std::chrono_literals;
using test::Snapshot;
using V = ParameterValue;

constexpr std::int64_t kSteps = 120;

Command set(std::int64_t step, std::vector<Parameter> parameters, bool atomic = true) {
  Command c;
  c.step = step;
  c.kind = CommandKind::SetParameters;
  c.parameters = std::move(parameters);
  c.atomic = atomic;
  c.source = "test";
  return c;
}

Command simple(std::int64_t step, CommandKind kind, std::int64_t steps = 0) {
  Command c;
  c.step = step;
  c.kind = kind;
  c.steps = steps;
  c.source = "test";
  return c;
}

CommandResult wait(std::future<CommandResult>& f) {
  if (f.wait_for(20s) != std::future_status::ready) throw std::runtime_error("no result within 20 s");
  return f.get();
}

// Waits for a paused loop that carries out a `step N` to reach step `want`, not for a time: a pause
// is answered "already paused" at the boundary it is applied at and leaves the stepping alone, so
// it is probed (at most 2,000 times, 1 ms apart) until the answer names a step >= `want`.
CommandResult paused_at(Controller& controller, std::int64_t want) {
  CommandResult r;
  for (int i = 0; i < 2000; ++i) {
    std::future<CommandResult> probe = controller.submit(simple(Command::kNextStep, CommandKind::Pause));
    r = wait(probe);
    if (r.step >= want) break;
    std::this_thread::sleep_for(1ms);
  }
  return r;
}

void expect_same_runs(const std::vector<Snapshot>& a, const std::vector<Snapshot>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a[i].step, b[i].step) << "snapshot " << i;
    ASSERT_TRUE(test::same_bits(a[i].state, b[i].state)) << "step " << a[i].step;
  }
}

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  if (at == std::string::npos || text.find(from, at + 1) != std::string::npos) {
    throw std::runtime_error("not one occurrence of " + from);
  }
  return text.replace(at, from.size(), to);
}

// A pass of the scene on another thread, with the controller.
struct AsyncRun {
  AsyncRun(const Scene& scene, std::int64_t steps, Controller& controller)
      : result(std::async(std::launch::async,
                          [&scene, steps, &controller] { return test::run(scene, steps, &controller); })) {}
  std::vector<Snapshot> get() {
    if (result.wait_for(60s) != std::future_status::ready) throw std::runtime_error("the run did not end");
    return result.get();
  }
  std::future<std::vector<Snapshot>> result;
};

TEST(Controller, WithNoCommandsTheRunIsTheRunWithoutControl) {
  const Scene scene = test::control_scene();
  Controller controller(scene, kSteps, RunSettings{0.0, 1, false});
  expect_same_runs(test::run(scene, kSteps, &controller), test::run(scene, kSteps));
}

// Each physical parameter set at step 0 against the scene file edited the same way, bit for bit.
TEST(ControllerSetParameters, AtStepZeroEqualsTheSceneFileEditedTheSameWay) {
  struct Edit {
    const char* name;
    V value;
    const char* from;
    const char* to;
  };
  const std::vector<Edit> edits = {
      {"forces.0.fx", V::of_double(1.5), R"(fx="0.0" fy="-9.81")", R"(fx="1.5" fy="-9.81")"},
      {"forces.0.fy", V::of_double(-3.7), R"(fx="0.0" fy="-9.81")", R"(fx="0.0" fy="-3.7")"},
      {"forces.1.beta", V::of_double(0.9), R"(beta="0.2")", R"(beta="0.9")"},
      {"forces.1.fx", V::of_double(-2.0), R"(fx="1.0" fy="0.5")", R"(fx="-2.0" fy="0.5")"},
      {"forces.1.fy", V::of_double(3.0), R"(fx="1.0" fy="0.5")", R"(fx="1.0" fy="3.0")"},
      {"forces.1.pointsperedge", V::of_integer(11), R"(pointsperedge="3")", R"(pointsperedge="11")"},
      {"forces.2.fx", V::of_double(-0.75), R"(fx="0.25" fy="0.0")", R"(fx="-0.75" fy="0.0")"},
      {"forces.2.fy", V::of_double(2.0), R"(fx="0.25" fy="0.0")", R"(fx="0.25" fy="2.0")"},
      {"springs.0.k", V::of_double(12.0), R"(k="5.0" l0="4.0")", R"(k="12.0" l0="4.0")"},
      {"springs.0.l0", V::of_double(2.0), R"(k="5.0" l0="4.0")", R"(k="5.0" l0="2.0")"},
      {"springs.1.k", V::of_double(3.0), R"(k="20.0" l0="3.0")", R"(k="3.0" l0="3.0")"},
      {"springs.1.l0", V::of_double(0.0), R"(k="20.0" l0="3.0")", R"(k="20.0" l0="0.0")"},
  };
  const Scene scene = test::control_scene();
  const std::vector<Snapshot> unchanged = test::run(scene, kSteps);
  for (const Edit& e : edits) {
    SCOPED_TRACE(e.name);
    Controller controller(scene, kSteps, RunSettings{0.0, 1, false});
    std::future<CommandResult> result = controller.submit(set(0, {{e.name, e.value}}));
    const std::vector<Snapshot> changed = test::run(scene, kSteps, &controller);
    const CommandResult r = wait(result);
    EXPECT_TRUE(r.successful) << r.message;
    EXPECT_EQ(r.step, 0);
    EXPECT_EQ(controller.get({e.name})[0], e.value);
    const Scene edited = test::scene_from(replaced(test::control_scene_text(), e.from, e.to));
    expect_same_runs(changed, test::run(edited, kSteps));
    EXPECT_FALSE(test::same_bits(changed.back().state, unchanged.back().state));  // the change mattered
  }
}

TEST(ControllerSetParameters, AtStepKActsFromThatBoundaryOn) {
  const Scene scene = test::control_scene();
  Controller controller(scene, kSteps, RunSettings{0.0, 1, false});
  std::future<CommandResult> result = controller.submit(set(40, {{"forces.0.fy", V::of_double(4.0)}}));
  const std::vector<Snapshot> changed = test::run(scene, kSteps, &controller);
  EXPECT_EQ(wait(result).step, 40);
  const std::vector<Snapshot> unchanged = test::run(scene, kSteps);
  for (std::size_t i = 0; i <= 40; ++i)
    EXPECT_TRUE(test::same_bits(changed[i].state, unchanged[i].state)) << i;
  EXPECT_FALSE(test::same_bits(changed[41].state, unchanged[41].state));
}

// A command's answer (and its observers) come after the values are published: a read made on
// hearing the answer sees the change (a Foxglove getParameters right after a setParameters).
TEST(ControllerSetParameters, AReadOnHearingTheAnswerSeesTheChange) {
  const Scene scene = test::control_scene();
  Controller controller(scene, kSteps, RunSettings{0.0, 1, false});
  std::vector<std::optional<V>> seen_by_observer, seen_by_caller;
  controller.on_command([&](const Command&, const CommandResult&) {
    seen_by_observer.push_back(controller.get({"forces.0.fy"})[0]);
  });
  controller.submit(set(10, {{"forces.0.fy", V::of_double(-2.0)}}), [&](const CommandResult&) {
    seen_by_caller.push_back(controller.get({"forces.0.fy"})[0]);
  });
  controller.submit(set(10, {{"forces.0.fy", V::of_double(-3.0)}}), [&](const CommandResult&) {
    seen_by_caller.push_back(controller.get({"forces.0.fy"})[0]);
  });
  (void)test::run(scene, kSteps, &controller);
  // Both applied at the boundary of step 10, then answered: each read sees the boundary's result.
  EXPECT_EQ(seen_by_caller, (std::vector<std::optional<V>>{V::of_double(-3.0), V::of_double(-3.0)}));
  EXPECT_EQ(seen_by_observer, seen_by_caller);
}

TEST(ControllerSetParameters, AnAtomicBatchWithOneBadParameterChangesNothing) {
  const Scene scene = test::control_scene();
  Controller controller(scene, kSteps, RunSettings{0.0, 1, false});
  std::future<CommandResult> result = controller.submit(set(
      0,
      {{"forces.0.fy", V::of_double(-1.0)}, {"rate", V::of_double(3.0)}, {"springs.0.k", V::of_integer(3)}}));
  const std::vector<Snapshot> run = test::run(scene, kSteps, &controller);
  const CommandResult r = wait(result);
  EXPECT_FALSE(r.successful);
  ASSERT_EQ(r.results.size(), 1u);
  EXPECT_NE(r.results[0].reason.find("springs.0.k"), std::string::npos) << r.results[0].reason;
  expect_same_runs(run, test::run(scene, kSteps));
  EXPECT_EQ(controller.get({"forces.0.fy"})[0], V::of_double(-9.81));
  EXPECT_EQ(controller.settings().rate, 0.0);
  EXPECT_EQ(controller.counters().parameter_changes, 0u);
}

TEST(ControllerSetParameters, NonAtomicGivesEachParameterItsResult) {
  const Scene scene = test::control_scene();
  Controller controller(scene, kSteps, RunSettings{0.0, 1, false});
  std::future<CommandResult> result = controller.submit(set(
      0, {{"forces.0.fy", V::of_double(-3.7)}, {"springs.0.k", V::of_integer(3)}, {"dt", V::of_double(1.0)}},
      false));
  const std::vector<Snapshot> run = test::run(scene, kSteps, &controller);
  const CommandResult r = wait(result);
  EXPECT_FALSE(r.successful);  // not all of them
  ASSERT_EQ(r.results.size(), 3u);
  EXPECT_TRUE(r.results[0].successful);
  EXPECT_FALSE(r.results[1].successful);
  EXPECT_NE(r.results[2].reason.find("read-only"), std::string::npos);
  const Scene edited =
      test::scene_from(replaced(test::control_scene_text(), R"(fy="-9.81")", R"(fy="-3.7")"));
  expect_same_runs(run, test::run(edited, kSteps));
  EXPECT_EQ(controller.counters().parameter_changes, 1u);
}

// Scheduled commands: deterministic, no threads.
TEST(ControllerPause, PauseStepResumeGiveTheStatesOfAnUnpausedRun) {
  const Scene scene = test::control_scene();
  Controller controller(scene, kSteps, RunSettings{0.0, 1, false});
  std::future<CommandResult> pause = controller.submit(simple(10, CommandKind::Pause));
  std::future<CommandResult> step = controller.submit(simple(10, CommandKind::Step, 5));
  std::future<CommandResult> resume = controller.submit(simple(15, CommandKind::Resume));
  const std::vector<Snapshot> run = test::run(scene, kSteps, &controller);
  EXPECT_TRUE(wait(pause).successful);
  const CommandResult stepped = wait(step);
  EXPECT_TRUE(stepped.successful) << stepped.message;
  EXPECT_EQ(stepped.step, 10);
  EXPECT_EQ(stepped.ends_at, 15);
  EXPECT_EQ(wait(resume).step, 15);
  expect_same_runs(run, test::run(scene, kSteps));
}

// stop_stepping (a SimulateSteps cancel) ends a `step N` at its boundary, the run paused there;
// a pause leaves the stepping alone; not stepping, stop_stepping does nothing.
TEST(ControllerStopStepping, EndsAStepNAtItsBoundary) {
  const Scene scene = test::control_scene();
  const auto session = [&](bool stop) {
    Controller controller(scene, kSteps, RunSettings{0.0, 1, false});
    controller.end_when_idle(true);  // offline: the pass ends where the loop would idle
    std::future<CommandResult> idle = controller.submit(simple(5, CommandKind::StopStepping));
    (void)controller.submit(simple(10, CommandKind::Pause));
    (void)controller.submit(simple(10, CommandKind::Step, 50));
    std::future<CommandResult> paused = controller.submit(simple(20, CommandKind::Pause));
    std::optional<std::future<CommandResult>> stopped;
    if (stop) stopped = controller.submit(simple(20, CommandKind::StopStepping));
    const std::vector<Snapshot> run = test::run(scene, kSteps, &controller);
    const CommandResult not_stepping = wait(idle);
    EXPECT_TRUE(not_stepping.successful);
    EXPECT_NE(not_stepping.message.find("not stepping at step 5"), std::string::npos) << not_stepping.message;
    EXPECT_NE(wait(paused).message.find("already paused"), std::string::npos);
    if (stopped) {
      const CommandResult r = wait(*stopped);
      EXPECT_TRUE(r.successful);
      EXPECT_NE(r.message.find("stopped stepping at step 20 with 40 steps left"), std::string::npos)
          << r.message;
    }
    EXPECT_EQ(run.back().step, controller.ended_paused().value_or(-1));
    return run;
  };
  const std::vector<Snapshot> stopped = session(true);
  EXPECT_EQ(stopped.back().step, 20);
  const std::vector<Snapshot> stepped_on = session(false);
  EXPECT_EQ(stepped_on.back().step, 60);
  const std::vector<Snapshot> plain = test::run(scene, 20);
  EXPECT_EQ(stopped.back(), plain.back()) << "the stop changes where the run idles, not its states";
}

// A live session: another thread pauses, steps, checks where the run idles, and resumes.
TEST(ControllerPause, FromAnotherThreadStepNAdvancesExactlyNSteps) {
  const Scene scene = test::control_scene();
  Controller controller(scene, kSteps, RunSettings{0.0, 1, true});  // starts paused at step 0
  AsyncRun running(scene, kSteps, controller);
  std::future<CommandResult> step = controller.submit(simple(Command::kNextStep, CommandKind::Step, 7));
  const CommandResult stepped = wait(step);
  ASSERT_TRUE(stepped.successful) << stepped.message;
  EXPECT_EQ(stepped.step, 0);
  const CommandResult probed = paused_at(controller, 7);  // the loop idles at step 7, not beyond
  EXPECT_EQ(probed.step, 7) << probed.message;
  EXPECT_NE(probed.message.find("already paused"), std::string::npos);
  std::future<CommandResult> running_step =
      controller.submit(simple(Command::kNextStep, CommandKind::Step, 0));
  EXPECT_FALSE(wait(running_step).successful);  // steps >= 1
  std::future<CommandResult> resume = controller.submit(simple(Command::kNextStep, CommandKind::Resume));
  EXPECT_EQ(wait(resume).step, 7);
  expect_same_runs(running.get(), test::run(scene, kSteps));
}

TEST(ControllerStep, IsRefusedWhileRunningAndPastTheLastStep) {
  const Scene scene = test::control_scene();
  Controller controller(scene, kSteps, RunSettings{0.0, 1, false});
  std::future<CommandResult> running = controller.submit(simple(5, CommandKind::Step, 3));
  std::future<CommandResult> pause = controller.submit(simple(8, CommandKind::Pause));
  std::future<CommandResult> too_far = controller.submit(simple(8, CommandKind::Step, kSteps));
  std::future<CommandResult> resume = controller.submit(simple(8, CommandKind::Resume));
  const std::vector<Snapshot> run = test::run(scene, kSteps, &controller);
  const CommandResult r = wait(running);
  EXPECT_FALSE(r.successful);
  EXPECT_NE(r.message.find("only while paused"), std::string::npos) << r.message;
  EXPECT_TRUE(wait(pause).successful);
  EXPECT_FALSE(wait(too_far).successful);
  EXPECT_TRUE(wait(resume).successful);
  expect_same_runs(run, test::run(scene, kSteps));
}

TEST(ControllerReset, ReproducesTheRunFromStepZeroWithTheScenesParameters) {
  const Scene scene = test::control_scene();
  Controller controller(scene, kSteps, RunSettings{0.0, 1, false});
  std::future<CommandResult> change = controller.submit(set(5, {{"forces.0.fy", V::of_double(2.0)}}));
  std::future<CommandResult> reset = controller.submit(simple(30, CommandKind::Reset));
  const std::vector<Snapshot> run = test::run(scene, kSteps, &controller);
  EXPECT_TRUE(wait(change).successful);
  const CommandResult r = wait(reset);
  EXPECT_TRUE(r.successful) << r.message;
  EXPECT_EQ(r.step, 30);
  const std::vector<Snapshot> plain = test::run(scene, kSteps);
  // begin (step 0), steps 1..30, then steps 1..kSteps again after the reset.
  ASSERT_EQ(run.size(), 1 + 30 + static_cast<std::size_t>(kSteps));
  for (std::size_t i = 0; i <= 5; ++i) EXPECT_TRUE(test::same_bits(run[i].state, plain[i].state)) << i;
  EXPECT_FALSE(test::same_bits(run[30].state, plain[30].state));
  for (std::int64_t k = 1; k <= kSteps; ++k) {
    const Snapshot& again = run[30 + static_cast<std::size_t>(k)];
    ASSERT_EQ(again.step, k);
    ASSERT_TRUE(test::same_bits(again.state, plain[static_cast<std::size_t>(k)].state)) << "step " << k;
  }
  EXPECT_EQ(controller.get({"forces.0.fy"})[0], V::of_double(-9.81));  // the scene's value again
}

TEST(ControllerImpulse, EqualsWorldApplyImpulseAtThatStep) {
  const Scene scene = test::control_scene();
  Controller controller(scene, kSteps, RunSettings{0.0, 1, false});
  Command c = simple(25, CommandKind::Impulse);
  c.impulse = {1, {0.5, -2.0}, {0.3, 0.1}};
  std::future<CommandResult> result = controller.submit(c);
  const std::vector<Snapshot> run = test::run(scene, kSteps, &controller);
  const CommandResult r = wait(result);
  ASSERT_TRUE(r.successful) << r.message;
  EXPECT_EQ(r.step, 25);
  Result<World> world = World::create(scene.world);
  ASSERT_TRUE(world.ok());
  for (int k = 0; k < 25; ++k) world.value().step();
  ASSERT_TRUE(world.value().apply_impulse(BodyId{1}, {0.5, -2.0}, {0.3, 0.1}).ok());
  for (std::int64_t k = 25; k < kSteps; ++k) world.value().step();
  EXPECT_TRUE(test::same_bits(run.back().state, test::snapshot(world.value()).state));
}

TEST(ControllerImpulse, RefusesBadRequestsAndTheRunGoesOnUnchanged) {
  const Scene scene = test::control_scene();
  Controller controller(scene, kSteps, RunSettings{0.0, 1, false});
  std::vector<std::future<CommandResult>> results;
  for (ImpulseArgs a : {ImpulseArgs{2, {1.0, 0.0}, {0.0, 0.0}}, ImpulseArgs{-1, {1.0, 0.0}, {0.0, 0.0}},
                        ImpulseArgs{0, {std::nan(""), 0.0}, {0.0, 0.0}},
                        ImpulseArgs{0, {1e300, 0.0}, {0.0, 0.0}}, ImpulseArgs{0, {1.0, 0.0}, {0.0, 1e308}}}) {
    Command c = simple(3, CommandKind::Impulse);
    c.impulse = a;
    results.push_back(controller.submit(c));
  }
  const std::vector<Snapshot> run = test::run(scene, kSteps, &controller);
  for (auto& f : results) {
    const CommandResult r = wait(f);
    EXPECT_FALSE(r.successful);
    EXPECT_NE(r.message.find("apply_impulse"), std::string::npos) << r.message;
  }
  expect_same_runs(run, test::run(scene, kSteps));
}

TEST(ControllerSettings, RateAndPublishEveryReachTheListenerAndRebaseTheSinks) {
  const Scene scene = test::control_scene();
  Controller controller(scene, kSteps, RunSettings{0.0, 1, false});
  std::vector<RunSettings> heard;
  controller.on_settings([&](const RunSettings& s) { heard.push_back(s); });
  std::future<CommandResult> r =
      controller.submit(set(12, {{"rate", V::of_double(1e6)}, {"publish_every", V::of_integer(4)}}));
  Result<Driver> driver = Driver::create(scene);
  ASSERT_TRUE(driver.ok());
  test::RecordingSink sink;
  driver.value().add(sink);
  DriverOptions options;
  options.steps = kSteps;
  options.control = &controller;
  ASSERT_TRUE(driver.value().run_pass(options).ok());
  EXPECT_TRUE(wait(r).successful);
  ASSERT_EQ(heard.size(), 1u);
  EXPECT_EQ(heard[0].rate, 1e6);
  EXPECT_EQ(heard[0].publish_every, 4);
  EXPECT_EQ(sink.rebases, 1);
  expect_same_runs(sink.snapshots, test::run(scene, kSteps));  // pace is wall time only
}

TEST(ControllerCommands, ForABoundaryThatHasPassedFail) {
  const Scene scene = test::control_scene();
  Controller controller(scene, kSteps, RunSettings{0.0, 1, true});
  AsyncRun running(scene, kSteps, controller);
  std::future<CommandResult> step = controller.submit(simple(Command::kNextStep, CommandKind::Step, 10));
  ASSERT_TRUE(wait(step).successful);
  ASSERT_EQ(paused_at(controller, 10).step, 10);  // step 3 has passed
  std::future<CommandResult> late = controller.submit(set(3, {{"rate", V::of_double(1.0)}}));
  const CommandResult r = wait(late);
  EXPECT_FALSE(r.successful);
  EXPECT_NE(r.message.find("step 3 has passed"), std::string::npos) << r.message;
  std::future<CommandResult> resume = controller.submit(simple(Command::kNextStep, CommandKind::Resume));
  EXPECT_TRUE(wait(resume).successful);
  running.get();
}

TEST(ControllerObservers, EveryObserverSeesWhatEachCommandChanged) {
  const Scene scene = test::control_scene();
  Controller controller(scene, kSteps, RunSettings{0.0, 1, false});
  std::vector<std::string> first, second;
  std::vector<std::vector<Parameter>> changed;
  controller.on_command([&](const Command& c, const CommandResult& r) {
    first.push_back(to_string(c.kind));
    changed.push_back(r.changed);
  });
  controller.on_command([&](const Command& c, const CommandResult&) { second.push_back(to_string(c.kind)); });
  controller.submit(set(2, {{"forces.0.fy", V::of_double(-3.0)}, {"bodies", V::of_integer(5)}}, false));
  controller.submit(simple(4, CommandKind::Pause, 0));
  controller.submit(simple(4, CommandKind::Pause, 0));  // already paused: nothing changed
  controller.submit(simple(4, CommandKind::Step, 3));
  controller.submit(simple(7, CommandKind::Resume));
  controller.submit(simple(9, CommandKind::Reset));
  test::run(scene, 12, &controller);
  EXPECT_EQ(first, (std::vector<std::string>{"set_parameters", "pause", "pause", "step", "resume", "reset"}));
  EXPECT_EQ(second, first);
  ASSERT_EQ(changed.size(), 6u);
  EXPECT_EQ(changed[0], (std::vector<Parameter>{{"forces.0.fy", V::of_double(-3.0)}}));  // bodies refused
  EXPECT_EQ(changed[1], (std::vector<Parameter>{{"paused", V::of_bool(true)}}));
  EXPECT_TRUE(changed[2].empty());
  EXPECT_TRUE(changed[3].empty());
  EXPECT_EQ(changed[4], (std::vector<Parameter>{{"paused", V::of_bool(false)}}));
  EXPECT_EQ(changed[5],
            (std::vector<Parameter>{{"forces.0.fy", V::of_double(-9.81)}}));  // back to the scene's
}

TEST(ControlServices, OneMappingOfRequestsAndReplies) {
  const auto services = control_services();
  ASSERT_EQ(services.size(), 5u);
  EXPECT_EQ(services[0].name, "pause");
  EXPECT_EQ(services[3].type, "rbsim_msgs/srv/Step");
  EXPECT_EQ(services[4].kind, CommandKind::Impulse);
  EXPECT_EQ(command_for(CommandKind::Reset, msgs::TriggerRequest{}).kind, CommandKind::Reset);
  const Command step = command_for(msgs::StepRequest{7});
  EXPECT_EQ(step.kind, CommandKind::Step);
  EXPECT_EQ(step.steps, 7);
  const Command impulse = command_for(msgs::ApplyImpulseRequest{3, 1.0, 2.0, 0.5, -0.5});
  EXPECT_EQ(impulse.impulse.body, 3);
  EXPECT_EQ(impulse.impulse.impulse, Vec2(1.0, 2.0));
  EXPECT_EQ(impulse.impulse.point, Vec2(0.5, -0.5));
  CommandResult r;
  r.successful = true;
  r.message = "done";
  r.step = 12;
  EXPECT_EQ(step_response(r), (msgs::StepResponse{true, "done", 12}));
  EXPECT_EQ(impulse_response(r), (msgs::ApplyImpulseResponse{true, "done", 12}));
  EXPECT_EQ(trigger_response(r), (msgs::TriggerResponse{true, "done"}));
  r.ends_at = 17;  // a step N: where the stepping ends
  EXPECT_EQ(step_response(r), (msgs::StepResponse{true, "done", 17}));
  EXPECT_EQ(impulse_response(r).step, 12u);
  r.successful = false;
  r.step = Command::kNextStep;  // never applied
  EXPECT_EQ(step_response(r).step, 0u);
}

TEST(ControllerClose, AnswersWhatIsQueuedAndRefusesLaterCommands) {
  const Scene scene = test::control_scene();
  std::future<CommandResult> never;
  {
    Controller controller(scene, 10, RunSettings{0.0, 1, false});
    never = controller.submit(set(50, {{"rate", V::of_double(1.0)}}));  // past the run's end
    test::run(scene, 10, &controller);
    controller.close("the node stopped");
    std::future<CommandResult> after = controller.submit(simple(Command::kNextStep, CommandKind::Pause));
    const CommandResult r = wait(after);
    EXPECT_FALSE(r.successful);
    EXPECT_NE(r.message.find("the node stopped"), std::string::npos);
  }
  EXPECT_FALSE(wait(never).successful);  // answered when the controller went away
}

// A running loop (not paused, nothing queued) ends its pass at its next boundary once closed,
// rather than running on to its last step.
TEST(ControllerClose, EndsARunningPassAtItsNextBoundary) {
  const Scene scene = test::control_scene();
  constexpr std::int64_t kMany = 1'000'000'000;  // minutes of stepping if close() did not end it
  static std::atomic<bool> give_up{false};       // ends the pass should close() not
  Controller controller(scene, kMany, RunSettings{0.0, 1, false});
  Result<Driver> driver = Driver::create(scene);
  ASSERT_TRUE(driver);
  ASSERT_TRUE(driver.value().begin());
  std::future<Result<PassEnd>> pass = std::async(std::launch::async, [&] {
    DriverOptions options;
    options.steps = kMany;
    options.control = &controller;
    options.stop = [] { return give_up.load(); };
    return driver.value().run(options);
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  controller.close("the node stopped");
  const bool ended = pass.wait_for(std::chrono::seconds(10)) == std::future_status::ready;
  give_up = true;
  ASSERT_TRUE(ended) << "still stepping 10 s after close()";
  const Result<PassEnd> end = pass.get();
  ASSERT_TRUE(end);
  EXPECT_EQ(end.value(), PassEnd::Stopped);
  EXPECT_LT(driver.value().world().step_index(), kMany);
}

// Several threads submit parameter sets, bad sets, reads and `step 1` requests while the run,
// paused, advances one step per request; every request is answered at a boundary, each thread's
// in order, and the physics is untouched.
TEST(ControllerStress, CommandsFromManyThreadsApplyAtBoundaries) {
  constexpr int kThreads = 4, kPerThread = 60;
  const Scene scene = test::control_scene();
  const std::int64_t steps =
      kThreads * kPerThread + 1;  // the run idles at the last step but one until resumed
  Controller controller(scene, steps, RunSettings{0.0, 1, true});
  std::vector<std::int64_t> boundaries_seen;
  std::mutex seen_mutex;
  controller.on_command([&](const Command& c, const CommandResult&) {
    const std::lock_guard lock(seen_mutex);
    boundaries_seen.push_back(c.step);
  });
  AsyncRun running(scene, steps, controller);
  std::vector<std::thread> threads;
  std::atomic<int> failures{0};
  std::atomic<std::uint64_t> good_sets{0};
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&, t] {
      std::int64_t last = -1;
      for (int k = 0; k < kPerThread; ++k) {
        std::vector<std::future<CommandResult>> mine;
        mine.push_back(controller.submit(set(Command::kNextStep, {{"rate", V::of_double(1.0 + t + k)}})));
        mine.push_back(controller.submit(set(Command::kNextStep, {{"publish_every", V::of_integer(0)}})));
        mine.push_back(controller.submit(simple(Command::kNextStep, CommandKind::Step, 1)));
        (void)controller.get({"rate", "paused"});
        (void)controller.list({}, kDepthRecursive);
        for (std::size_t i = 0; i < mine.size(); ++i) {
          const CommandResult r = wait(mine[i]);
          const bool expected = i != 1;
          if (r.successful != expected || r.step < last || r.step > steps) ++failures;
          last = r.step;
        }
        ++good_sets;
      }
    });
  }
  for (std::thread& th : threads) th.join();
  std::future<CommandResult> resume = controller.submit(simple(Command::kNextStep, CommandKind::Resume));
  EXPECT_TRUE(wait(resume).successful);
  const std::vector<Snapshot> run = running.get();
  EXPECT_EQ(failures.load(), 0);
  expect_same_runs(run, test::run(scene, steps));
  const ControlCounters counted = controller.counters();
  EXPECT_EQ(counted.parameter_changes, good_sets.load());
  EXPECT_EQ(counted.commands, static_cast<std::uint64_t>(kThreads * kPerThread * 3 + 1));
  EXPECT_EQ(counted.queries, static_cast<std::uint64_t>(kThreads * kPerThread * 2));
  for (std::int64_t s : boundaries_seen) EXPECT_TRUE(s >= 0 && s <= steps) << s;
}

}  // namespace
}  // namespace rbsim::control
