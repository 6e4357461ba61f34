// Worlds through the Controller (rbsim/control.hpp): load_world replaces the world at a step
// boundary, stopped at its step 0, and then steps bit for bit as an offline run of the loaded scene
// alone; a scene that does not load leaves the world untouched; unload_world leaves no world, where
// every command that needs one is refused; the commands as rbsim_msgs/msg/Command.
#include <gtest/gtest.h>

#include <algorithm>
#include <future>
#include <string>
#include <vector>

#include "control_test_util.hpp"
#include "rbsim/command_script.hpp"
#include "rbsim/control.hpp"

namespace rbsim::control {
namespace {

using test::Snapshot;

constexpr std::int64_t kSteps = 120;

// Another world: one body of its own, another dt and integrator, 30 steps long.
const std::string kOtherWorld = test::square_world_text("0.15");

Command at(std::int64_t step, CommandKind kind) {
  Command c;
  c.step = step;
  c.kind = kind;
  c.source = "test";
  return c;
}
Command load(std::int64_t step, std::string text, std::string uri = "other.xml") {
  Command c = at(step, CommandKind::LoadWorld);
  c.world.resource = std::move(text);
  c.world.uri = std::move(uri);
  return c;
}

// The snapshots of a run of the control scene steered by `commands` (epochs as a recording's:
// each restart starts one), with the outputs' restructure() calls.
struct Steered {
  std::vector<Snapshot> snapshots;
  std::vector<Entities> entities;
  std::vector<std::string> descriptions;  // of each restructure's scene, while the controller kept it
  std::vector<std::string> mismatches;
  WorldInfo world;
};
Steered steered(const Scene& scene, std::vector<ScriptedCommand> commands) {
  ScriptedRun run(scene, kSteps, std::move(commands));
  Steered s;
  s.snapshots = test::run(scene, kSteps, &run.controller(), &s.entities, true, &s.descriptions);
  s.world = run.controller().world_info();
  (void)run.finish("session");
  s.mismatches = run.mismatches();
  return s;
}

TEST(ControllerLoadWorld, StopsAtStepZeroAndStepsAsTheLoadedSceneAlone) {
  const Scene scene = test::control_scene();
  // A spawn, then the other world at step 10, played from its step 0: the world's own length.
  const Steered s = steered(scene, {{test::spawn_command(5, "crate", Vec2(0.0, 3.0), 0.0), true, "spawn", 0},
                                    {load(10, kOtherWorld), true, "load", 0},
                                    {at(0, CommandKind::Resume), true, "play", 1}});
  ASSERT_TRUE(s.mismatches.empty()) << s.mismatches.front();
  // After the spawn's change, the load's: world 1, its scene, its one body named as a scene's.
  ASSERT_EQ(s.entities.size(), 2u);
  EXPECT_EQ(s.entities[0].world, 0u);
  EXPECT_EQ(s.entities[1].world, 1u);
  EXPECT_EQ(s.descriptions[1], "a falling square");
  EXPECT_EQ(s.entities[1].body_names, (std::vector<std::string>{"body_0"}));
  EXPECT_GT(s.entities[1].epoch, s.entities[0].epoch);
  EXPECT_EQ(s.world.name, "other");
  EXPECT_EQ(s.world.uri, "other.xml");
  EXPECT_EQ(s.world.dt, 0.005);
  EXPECT_EQ(s.world.number, 1u);

  // The loaded world from its step 0 (the sinks' restructure at step 0, then steps 1..30) is the
  // other scene run alone, bit for bit.
  const Scene other = test::scene_from(kOtherWorld);
  const std::vector<Snapshot> alone = test::run(other, other.step_count());
  ASSERT_EQ(alone.size(), 31u) << "the other scene is 30 steps long";
  const auto first = std::find_if(s.snapshots.begin(), s.snapshots.end(),
                                  [&](const Snapshot& x) { return x.state.size() == alone[0].state.size(); });
  ASSERT_NE(first, s.snapshots.end());
  ASSERT_EQ(s.snapshots.end() - first, 30) << "steps 1..30 of the loaded world, then the pass ends";
  for (std::size_t k = 1; k < alone.size(); ++k) {
    const Snapshot& live = *(first + static_cast<std::ptrdiff_t>(k - 1));
    EXPECT_EQ(live.step, alone[k].step);
    EXPECT_TRUE(test::same_bits(live.state, alone[k].state)) << "step " << alone[k].step;
  }
}

TEST(ControllerLoadWorld, ASceneThatDoesNotLoadLeavesTheWorldUntouched) {
  const Scene scene = test::control_scene();
  Controller controller(scene, kSteps, RunSettings{0.0, 1, false});
  std::future<CommandResult> bad =
      controller.submit(load(3, "<scene>\n<rigidbodyvertex x=\"0\"/>\n</scene>\n"));
  std::future<CommandResult> empty = controller.submit(load(4, ""));
  const std::vector<Snapshot> snaps = test::run(scene, 20, &controller);
  const CommandResult r = bad.get();
  EXPECT_FALSE(r.successful);
  EXPECT_EQ(r.refusal, Refusal::BadResource);
  EXPECT_NE(r.message.find("other.xml:2:"), std::string::npos) << r.message;
  EXPECT_FALSE(empty.get().successful);
  EXPECT_EQ(controller.world_info().name, "control");
  EXPECT_TRUE(controller.world_info().loaded);
  EXPECT_EQ(snaps, test::run(scene, 20)) << "the world stepped on as if nothing was asked";
}

TEST(ControllerUnloadWorld, LeavesNoWorldWhereCommandsThatNeedOneAreRefused) {
  const Scene scene = test::control_scene();
  Command spawn = test::spawn_command(0, "crate", Vec2(0.0, 3.0), 0.0);
  const Steered s = steered(scene, {{at(7, CommandKind::UnloadWorld), true, "unload", 0},
                                    // No world: nothing to run, step, reset, spawn into or unload.
                                    {at(0, CommandKind::Resume), false, "play", 1},
                                    {at(0, CommandKind::Reset), false, "reset", 1},
                                    {spawn, false, "spawn", 1},
                                    {at(0, CommandKind::UnloadWorld), false, "unload again", 1},
                                    {at(0, CommandKind::Pause), true, "pause", 1},
                                    {load(0, kOtherWorld), true, "load", 1},
                                    {at(0, CommandKind::Resume), true, "play", 2}});
  ASSERT_TRUE(s.mismatches.empty()) << s.mismatches.front();
  ASSERT_EQ(s.entities.size(), 2u);
  EXPECT_TRUE(s.entities[0].body_names.empty()) << "no world: no bodies";
  EXPECT_EQ(s.entities[0].world, 1u);
  EXPECT_EQ(s.entities[1].world, 2u);
  EXPECT_TRUE(s.world.loaded);
  EXPECT_EQ(s.snapshots.back().step, 30) << "the loaded world ran to its end";
}

TEST(ControllerUnloadWorld, IsRefusedWhereTheOutputsCannotFollow) {
  const Scene scene = test::control_scene();
  Controller controller(scene, kSteps, RunSettings{0.0, 1, false});
  std::future<CommandResult> r = controller.submit(at(2, CommandKind::UnloadWorld));
  (void)test::run(scene, 5, &controller, nullptr, /*follows=*/false);
  const CommandResult got = r.get();
  EXPECT_FALSE(got.successful);
  EXPECT_NE(got.message.find("cannot follow"), std::string::npos) << got.message;
}

TEST(CommandMessage, LoadAndUnloadWorldRoundTripWithTheScenesText) {
  CommandResult ok;
  ok.successful = true;
  ok.step = 12;
  const msgs::CommandMessage m =
      to_message(load(Command::kNextStep, kOtherWorld, "worlds/other.xml"), ok, 4, 0.01);
  EXPECT_EQ(m.kind, msgs::CommandMessage::LoadWorld);
  Result<Command> back = from_message(m);
  ASSERT_TRUE(back.ok()) << back.error().message;
  EXPECT_EQ(back.value().kind, CommandKind::LoadWorld);
  EXPECT_EQ(back.value().world.resource, kOtherWorld);
  EXPECT_EQ(back.value().world.uri, "worlds/other.xml");
  EXPECT_EQ(back.value().step, 12);
  const msgs::CommandMessage u = to_message(at(3, CommandKind::UnloadWorld), ok, 5, 0.01);
  Result<Command> unload = from_message(u);
  ASSERT_TRUE(unload.ok()) << unload.error().message;
  EXPECT_EQ(unload.value().kind, CommandKind::UnloadWorld);
  msgs::CommandMessage bad = m;
  bad.parameters.pop_back();  // no uri
  EXPECT_FALSE(from_message(bad).ok());
  bad = u;
  bad.kind = 13;
  const Result<Command> unknown = from_message(bad);
  ASSERT_FALSE(unknown.ok());
  EXPECT_NE(unknown.error().message.find("0..12"), std::string::npos) << unknown.error().message;
}

}  // namespace
}  // namespace rbsim::control
