// The living world through the Controller (rbsim/control.hpp): spawn, delete and reset_spawned at
// step boundaries against an offline run of the scene file edited the same way, bit for bit;
// names never given twice; the parameter table following the springs; the commands as
// rbsim_msgs/msg/Command and as script entries.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <future>
#include <string>
#include <thread>

#include "control_test_util.hpp"
#include "rbsim/command_script.hpp"
#include "rbsim/control.hpp"

namespace rbsim::control {
namespace {

using namespace std::chrono_literals;
using test::Snapshot;

constexpr std::int64_t kSteps = 120;

using test::delete_command;
using test::kFragment;
using test::spawn_command;

// The control scene with the fragment's body as its body 2 and its springs as springs 2 and 3,
// which is what a spawn at step k must step as, from the states the live world had at k.
std::string edited_scene_text() {
  std::string text = test::control_scene_text();
  const std::string added = R"(
  <rigidbodyvertex x="-1" y="-1" m="1"/><rigidbodyvertex x="-1" y="1" m="1"/>
  <rigidbodyvertex x="3" y="0" m="1"/>
  <rigidbody p="7" p="8" p="9" vx="0.25" vy="-0.5" omega="0.75" r="0.2"/>
  <rigidbodyspringforce i="2" pix="0.5" piy="0.25" j="1" pjx="0.0" pjy="0.5" k="7.0" l0="1.5"/>
  <rigidbodyspringforce i="-1" pix="2.0" piy="6.0" j="2" pjx="0.0" pjy="0.0" k="3.0" l0="0.5"/>
</scene>)";
  return text.replace(text.rfind("</scene>"), 8, added);
}

CommandResult wait(std::future<CommandResult>& f) {
  if (f.wait_for(20s) != std::future_status::ready) throw std::runtime_error("no result within 20 s");
  return f.get();
}

// Runs `scene` from `start` (every body's state, as snapshot() orders it) at step `k` to kSteps.
std::vector<Snapshot> run_from(const Scene& scene, const Snapshot& start) {
  World w = World::create(scene.world).value();
  const std::int32_t n = w.body_count();
  for (std::int32_t b = 0; b < n; ++b) {
    const auto at = [&](int column) { return start.state[static_cast<std::size_t>(column * n + b)]; };
    w.set_state(BodyId{b}, BodyState{{at(0), at(1)}, at(2), {at(3), at(4)}, at(5)});
  }
  w.set_step_index(start.step);
  std::vector<Snapshot> out{test::snapshot(w)};
  while (w.step_index() < kSteps) {
    w.step();
    out.push_back(test::snapshot(w));
  }
  return out;
}

// The snapshots of a run from step `k` on.
std::vector<Snapshot> from_step(const std::vector<Snapshot>& run, std::int64_t k) {
  std::vector<Snapshot> out;
  for (const Snapshot& s : run) {
    if (s.step >= k) out.push_back(s);
  }
  return out;
}

void expect_same_runs(const std::vector<Snapshot>& a, const std::vector<Snapshot>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a[i].step, b[i].step) << "snapshot " << i;
    ASSERT_TRUE(test::same_bits(a[i].state, b[i].state)) << "step " << a[i].step;
  }
}

TEST(ControllerSpawn, AtStepKStepsAsTheEditedSceneFromThatState) {
  const Scene scene = test::control_scene();
  Controller controller(scene, kSteps, RunSettings{0.0, 1, false});
  std::future<CommandResult> spawned = controller.submit(spawn_command(40, "triangle", {1.5, 6.0}, 0.4));
  const std::vector<Snapshot> live = test::run(scene, kSteps, &controller);
  const CommandResult r = wait(spawned);
  ASSERT_TRUE(r.successful) << r.message;
  EXPECT_EQ(r.step, 40);
  EXPECT_EQ(r.entity, "triangle");
  EXPECT_EQ(r.body_id, 2);
  // The sink's snapshot at step 40 is the world before the spawn: the spawned body's state at
  // 40 is the pose and the fragment's velocities; the scene's bodies are as they were.
  const std::vector<Snapshot> after = from_step(live, 41);
  ASSERT_FALSE(after.empty());
  Snapshot start = from_step(live, 40).front();
  const auto n = static_cast<std::size_t>(2);
  std::vector<double> with(start.state.size() / n * 3);
  const double added[] = {1.5, 6.0, 0.4, 0.25, -0.5, 0.75};
  for (std::size_t column = 0; column < 6; ++column) {
    with[column * 3] = start.state[column * n];
    with[column * 3 + 1] = start.state[column * n + 1];
    with[column * 3 + 2] = added[column];
  }
  start.state = with;
  const std::vector<Snapshot> expected = run_from(test::scene_from(edited_scene_text()), start);
  expect_same_runs(after, from_step(expected, 41));
  // And the spawn mattered to the scene's bodies (the spring to body_1 pulls it).
  EXPECT_FALSE(
      test::same_bits(test::run(scene, kSteps).back().state,
                      std::vector<double>(live.back().state.begin(), live.back().state.begin() + 2)));
}

TEST(ControllerDelete, RemovesTheBodyAndNamesTheSpringsAttachedToIt) {
  const Scene scene = test::control_scene();
  Controller controller(scene, kSteps, RunSettings{0.0, 1, false});
  std::future<CommandResult> spawned = controller.submit(spawn_command(10, "triangle", {1.5, 6.0}, 0.0));
  std::future<CommandResult> deleted = controller.submit(delete_command(30, "body_1"));
  std::future<CommandResult> again = controller.submit(delete_command(31, "body_1"));
  std::future<CommandResult> nobody = controller.submit(delete_command(32, "crate"));
  std::vector<Entities> entities;
  const std::vector<Snapshot> live = test::run(scene, kSteps, &controller, &entities);
  ASSERT_TRUE(wait(spawned).successful);
  const CommandResult r = wait(deleted);
  ASSERT_TRUE(r.successful) << r.message;
  // body_1 held scene spring 0 (to body_0) and spawned spring 2 (from the triangle).
  EXPECT_EQ(r.removed_springs, (std::vector<std::int32_t>{0, 2}));
  EXPECT_NE(r.message.find("the springs attached to it: 0, 2"), std::string::npos) << r.message;
  EXPECT_EQ(r.removed,
            (std::vector<std::string>{"springs.0.k", "springs.0.l0", "springs.2.k", "springs.2.l0"}));
  const CommandResult twice = wait(again), none = wait(nobody);
  EXPECT_FALSE(twice.successful);
  EXPECT_EQ(twice.refusal, Refusal::NoSuchEntity);
  EXPECT_EQ(none.refusal, Refusal::NoSuchEntity);
  EXPECT_EQ(from_step(live, 31).front().state.size(), 12U);  // two bodies left
  EXPECT_EQ(controller.get({"bodies"})[0], ParameterValue::of_integer(2));
  EXPECT_EQ(controller.get({"springs.1.k"})[0], ParameterValue::of_double(20.0));
  EXPECT_EQ(controller.get({"springs.3.k"})[0], ParameterValue::of_double(3.0));
  EXPECT_FALSE(controller.get({"springs.0.k"})[0].has_value());
  // The outputs were told twice, with the names and colours in the world's order each time.
  ASSERT_EQ(entities.size(), 2U);
  EXPECT_EQ(entities[0].body_names, (std::vector<std::string>{"body_0", "body_1", "triangle"}));
  EXPECT_EQ(entities[0].spring_colors.size(), 4U);
  EXPECT_EQ(entities[0].body_colors[2], default_body_color(2));
  EXPECT_EQ(entities[0].epoch, 1U);
  EXPECT_EQ(entities[1].body_names, (std::vector<std::string>{"body_0", "triangle"}));
  EXPECT_EQ(entities[1].body_colors, (std::vector<Color>{scene.body_colors[0], default_body_color(2)}));
  EXPECT_EQ(entities[1].spring_colors.size(), 2U);
  EXPECT_EQ(entities[1].epoch, 2U);
}

// Changes due at one boundary reach the outputs one at a time, as a paused node's arrive, so a
// session and its re-run (which applies a step's commands together) write the same messages.
TEST(ControllerSpawn, ChangesAtOneBoundaryAreWrittenOneAtATime) {
  const Scene scene = test::control_scene();
  Controller controller(scene, kSteps, RunSettings{0.0, 1, false});
  std::vector<std::future<CommandResult>> results;
  results.push_back(controller.submit(spawn_command(5, "a", {1.5, 6.0}, 0.0)));
  results.push_back(controller.submit(spawn_command(5, "b", {-4.0, 6.0}, 1.0)));
  results.push_back(controller.submit(delete_command(5, "a")));
  std::vector<Entities> told;
  const std::vector<Snapshot> live = test::run(scene, kSteps, &controller, &told);
  for (auto& r : results) ASSERT_TRUE(wait(r).successful);
  ASSERT_EQ(told.size(), 3u);
  EXPECT_EQ(told[0].body_names, (std::vector<std::string>{"body_0", "body_1", "a"}));
  EXPECT_EQ(told[1].body_names, (std::vector<std::string>{"body_0", "body_1", "a", "b"}));
  EXPECT_EQ(told[2].body_names, (std::vector<std::string>{"body_0", "body_1", "b"}));
  EXPECT_EQ(from_step(live, 6).front().state.size(), 3u * 6u);
}

// A running loop (rate above 0) steps before a live change that arrived after another held it (here
// submitted as the first applied), so a client spawning call after call cannot stop the clock; a
// loop as fast as it goes applies it at once, at the same boundary.
// A running node's changes take a bounded share of its loop: a live spawn that arrives after another
// waits while the loop steps on (rate > 0), where as fast as possible it applies at once. The run
// paces each step as a node does (its steps take wall time) and ends when the second spawn applied,
// so nothing here depends on how fast the machine is; 100,000 steps bound it.
TEST(ControllerSpawn, ARunningLoopStepsBeforeALiveChangeThatArrivedAfterAnother) {
  constexpr std::int64_t kLongRun = 100000;
  const Scene scene = test::control_scene();
  for (const double rate : {0.0, 1.0}) {
    Controller controller(scene, kLongRun, RunSettings{rate, 1, false});
    std::promise<CommandResult> second_done;
    std::future<CommandResult> second = second_done.get_future();
    CommandResult first;
    controller.submit(spawn_command(Command::kNextStep, "a", {1.5, 6.0}, 0.0), [&](const CommandResult& r) {
      first = r;
      controller.submit(spawn_command(Command::kNextStep, "b", {-4.0, 6.0}, 0.0),
                        [&](const CommandResult& b) {
                          second_done.set_value(b);
                          controller.close("the second spawn applied");  // the pass ends at the next boundary
                        });
    });
    Driver driver = Driver::create(scene).value();
    test::RecordingSink sink;
    driver.add(sink);
    DriverOptions options;
    options.steps = kLongRun;
    options.control = &controller;
    options.pace = [](const World&) { std::this_thread::sleep_for(100us); };
    ASSERT_TRUE(driver.run_pass(options).ok());
    ASSERT_TRUE(first.successful) << first.message;
    const CommandResult r = wait(second);
    ASSERT_TRUE(r.successful) << r.message;
    if (rate > 0.0) {
      EXPECT_GT(r.step, first.step);
    } else {
      EXPECT_EQ(r.step, first.step);
    }
  }
}

TEST(ControllerSpawn, NamesAreNeverGivenTwiceInASession) {
  const Scene scene = test::control_scene();
  Controller controller(scene, kSteps, RunSettings{0.0, 1, false});
  std::vector<std::future<CommandResult>> results;
  results.push_back(controller.submit(spawn_command(5, "crate", {0.0, 8.0}, 0.0)));
  results.push_back(controller.submit(spawn_command(6, "crate", {0.0, 9.0}, 0.0)));  // taken
  results.push_back(controller.submit(delete_command(7, "crate")));
  results.push_back(controller.submit(spawn_command(8, "crate", {0.0, 8.0}, 0.0)));  // used before
  Command renamed = spawn_command(9, "crate", {0.0, 8.0}, 0.0);
  renamed.spawn.allow_renaming = true;
  results.push_back(controller.submit(renamed));
  results.push_back(controller.submit(spawn_command(10, "", {0.0, 9.0}, 0.0)));
  results.push_back(controller.submit(spawn_command(11, "body_7", {0.0, 9.0}, 0.0)));
  (void)test::run(scene, kSteps, &controller);
  std::vector<CommandResult> r;
  for (auto& f : results) r.push_back(wait(f));
  EXPECT_TRUE(r[0].successful);
  EXPECT_EQ(r[1].refusal, Refusal::NameTaken);
  EXPECT_TRUE(r[2].successful);
  EXPECT_EQ(r[3].refusal, Refusal::NameTaken);
  EXPECT_NE(r[3].message.find("used earlier in the session"), std::string::npos) << r[3].message;
  EXPECT_EQ(r[4].entity, "crate_1");
  EXPECT_EQ(r[5].entity, "entity_1");
  EXPECT_EQ(r[4].body_id, 3);  // ids are never reused: the deleted crate had 2
  EXPECT_EQ(r[5].body_id, 4);
  EXPECT_FALSE(r[6].successful);  // body_<id> is the scene bodies' form
}

TEST(ControllerResetSpawned, RemovesWhatWasSpawnedAndLeavesTheSceneBodiesAsTheyAre) {
  const Scene scene = test::control_scene();
  Controller controller(scene, kSteps, RunSettings{0.0, 1, false});
  std::future<CommandResult> a = controller.submit(spawn_command(10, "a", {1.5, 6.0}, 0.0));
  std::future<CommandResult> b = controller.submit(spawn_command(12, "b", {-4.0, 6.0}, 1.0));
  Command reset;
  reset.step = 50;
  reset.kind = CommandKind::ResetSpawned;
  std::future<CommandResult> cleared = controller.submit(reset);
  const std::vector<Snapshot> live = test::run(scene, kSteps, &controller);
  ASSERT_TRUE(wait(a).successful && wait(b).successful);
  const CommandResult r = wait(cleared);
  ASSERT_TRUE(r.successful) << r.message;
  EXPECT_EQ(r.removed_springs.size(), 4U);
  // From step 50 the world is the scene's two bodies, in the state the spawned bodies' springs
  // had pulled them to: an offline run of the unedited scene from there.
  Snapshot at50 = from_step(live, 50).front();  // before the reset: four bodies
  ASSERT_EQ(at50.state.size(), 24U);
  std::vector<double> scene_bodies;
  for (std::size_t column = 0; column < 6; ++column) {
    scene_bodies.push_back(at50.state[column * 4]);
    scene_bodies.push_back(at50.state[column * 4 + 1]);
  }
  at50.state = scene_bodies;
  expect_same_runs(from_step(live, 51), from_step(run_from(scene, at50), 51));
  EXPECT_EQ(controller.get({"springs"})[0], ParameterValue::of_integer(2));
}

TEST(ControllerReset, ContinuesTheIdsAndKeepsTheNamesUsed) {
  const Scene scene = test::control_scene();
  Controller controller(scene, kSteps, RunSettings{0.0, 1, false});
  std::future<CommandResult> first = controller.submit(spawn_command(10, "crate", {1.5, 6.0}, 0.0));
  Command reset;
  reset.step = 20;
  reset.kind = CommandKind::Reset;
  std::future<CommandResult> was_reset = controller.submit(reset);
  const std::vector<Snapshot> live = test::run(scene, kSteps, &controller);
  ASSERT_TRUE(wait(first).successful);
  ASSERT_TRUE(wait(was_reset).successful);
  // After the reset the pass runs from step 0 again with the scene's two bodies only.
  EXPECT_EQ(live.back().state.size(), 12U);
  EXPECT_FALSE(controller.get({"springs.2.k"})[0].has_value());
  Controller next(scene, kSteps, RunSettings{0.0, 1, false});
  (void)next;
}

TEST(ControllerSpawn, IsRefusedWhereTheOutputsCannotFollow) {
  const Scene scene = test::control_scene();
  Controller controller(scene, kSteps, RunSettings{0.0, 1, false});
  std::future<CommandResult> spawned = controller.submit(spawn_command(5, "crate", {0.0, 8.0}, 0.0));
  const std::vector<Snapshot> live = test::run(scene, kSteps, &controller, nullptr, /*follows=*/false);
  const CommandResult r = wait(spawned);
  EXPECT_FALSE(r.successful);
  EXPECT_NE(r.message.find("cannot follow a world whose bodies change"), std::string::npos) << r.message;
  expect_same_runs(live, test::run(scene, kSteps));
}

TEST(ControllerSpawn, RefusesAFragmentThatDoesNotParseOrNamesNoBody) {
  const Scene scene = test::control_scene();
  Controller controller(scene, kSteps, RunSettings{0.0, 1, false});
  Command bad = spawn_command(5, "bad", {0.0, 8.0}, 0.0);
  bad.spawn.resource = "<scene><rigidbodyvertex x=\"0\" y=\"0\" m=\"-1\"/></scene>";
  bad.spawn.uri = "bad.xml";
  Command stranger = spawn_command(6, "stranger", {0.0, 8.0}, 0.0);
  const std::string named = R"(jbody="body_1")";
  stranger.spawn.resource.replace(stranger.spawn.resource.find(named), named.size(), R"(jbody="nobody")");
  std::future<CommandResult> r1 = controller.submit(bad);
  std::future<CommandResult> r2 = controller.submit(stranger);
  const std::vector<Snapshot> live = test::run(scene, kSteps, &controller);
  const CommandResult a = wait(r1), b = wait(r2);
  EXPECT_EQ(a.refusal, Refusal::BadResource);
  EXPECT_NE(a.message.find("bad.xml:1:"), std::string::npos) << a.message;
  EXPECT_EQ(b.refusal, Refusal::NoSuchEntity);
  EXPECT_NE(b.message.find("'nobody'"), std::string::npos) << b.message;
  expect_same_runs(live, test::run(scene, kSteps));
}

TEST(ControllerImpulse, NamesABodyByItsIdAfterEarlierOnesWereDeleted) {
  const Scene scene = test::control_scene();
  const auto deleted_then = [&](bool kick_it, CommandResult* gone_result) {
    Controller controller(scene, kSteps, RunSettings{0.0, 1, false});
    (void)controller.submit(delete_command(10, "body_0"));
    Command kick;
    kick.step = 20;
    kick.kind = CommandKind::Impulse;
    kick.impulse = ImpulseArgs{1, {0.0, kick_it ? 3.0 : 0.0}, {0.0, 0.0}};
    std::future<CommandResult> kicked = controller.submit(kick);
    kick.step = 21;
    kick.impulse.body = 0;
    std::future<CommandResult> gone = controller.submit(kick);
    std::vector<Snapshot> live = test::run(scene, kSteps, &controller);
    EXPECT_TRUE(wait(kicked).successful);
    *gone_result = wait(gone);
    return live;
  };
  CommandResult r;
  const std::vector<Snapshot> kicked = deleted_then(true, &r), still = deleted_then(false, &r);
  EXPECT_FALSE(r.successful);
  EXPECT_NE(r.message.find("no body 0 (the world has 1 bodies, ids from 0 to 1)"), std::string::npos)
      << r.message;
  // body_1 is the world's only body: the impulse of 3 N s gave it vy + 3 / M, M = 5, at step 20
  // (one step of wind drag later, within a few parts in a thousand).
  ASSERT_TRUE(test::same_bits(from_step(kicked, 20).front().state, from_step(still, 20).front().state));
  const Snapshot a = from_step(kicked, 21).front(), b = from_step(still, 21).front();
  ASSERT_EQ(a.state.size(), 6U);
  EXPECT_NEAR(a.state[4] - b.state[4], 3.0 / 5.0, 3e-3);
}

TEST(CommandMessage, SpawnDeleteAndResetSpawnedRoundTrip) {
  Command spawn = spawn_command(12, "ns/crate", {1.25, -2.5}, 0.375);
  spawn.spawn.uri = "/tmp/crate.xml";
  spawn.spawn.allow_renaming = true;
  CommandResult ok;
  ok.successful = true;
  ok.step = 12;
  ok.body_id = 9;
  const msgs::CommandMessage m = to_message(spawn, ok, 4, 0.01);
  EXPECT_EQ(m.kind, msgs::CommandMessage::SpawnEntity);
  EXPECT_EQ(m.body, 9U);
  Result<Command> back = from_message(m);
  ASSERT_TRUE(back.ok()) << back.error().message;
  EXPECT_EQ(back.value().kind, CommandKind::Spawn);
  EXPECT_EQ(back.value().spawn.resource, kFragment);
  EXPECT_EQ(back.value().spawn.uri, "/tmp/crate.xml");
  EXPECT_EQ(back.value().spawn.name, "ns/crate");
  EXPECT_TRUE(back.value().spawn.allow_renaming);
  EXPECT_EQ(back.value().spawn.position, Vec2(1.25, -2.5));
  EXPECT_EQ(back.value().spawn.theta, 0.375);
  EXPECT_TRUE(back.value().parameters.empty());

  const msgs::CommandMessage d = to_message(delete_command(13, "ns/crate"), ok, 5, 0.01);
  Result<Command> deleted = from_message(d);
  ASSERT_TRUE(deleted.ok());
  EXPECT_EQ(deleted.value().kind, CommandKind::Delete);
  EXPECT_EQ(deleted.value().entity, "ns/crate");

  Command clear;
  clear.kind = CommandKind::ResetSpawned;
  EXPECT_EQ(from_message(to_message(clear, ok, 6, 0.01)).value().kind, CommandKind::ResetSpawned);
}

TEST(CommandMessage, RefusesMissingOrMistypedSpawnArguments) {
  CommandResult ok;
  msgs::CommandMessage m = to_message(spawn_command(1, "a", {0.0, 0.0}, 0.0), ok, 7, 0.01);
  const msgs::CommandMessage full = m;
  m.parameters.erase(m.parameters.begin());  // no resource
  EXPECT_NE(from_message(m).error().message.find("command 7: spawn_entity: parameter 'resource' missing"),
            std::string::npos);
  m = full;
  m.parameters[4].value = ParameterValue::of_string("1");  // x
  EXPECT_NE(from_message(m).error().message.find("'x' is not a double"), std::string::npos)
      << from_message(m).error().message;
  m = full;
  m.parameters.push_back({"z", ParameterValue::of_double(1.0)});
  EXPECT_NE(from_message(m).error().message.find("unknown parameter 'z'"), std::string::npos);
  m = full;
  m.parameters.push_back(m.parameters[0]);
  EXPECT_NE(from_message(m).error().message.find("given twice"), std::string::npos);
  m = full;
  m.kind = 13;
  EXPECT_NE(from_message(m).error().message.find("unknown kind 13"), std::string::npos);
}

TEST(CommandScript, SpawnReadsItsFileNowAndNamesTheLineOfABadOne) {
  const std::filesystem::path dir = std::filesystem::path(::testing::TempDir()) / "rbsim_spawn_script";
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "triangle.xml") << kFragment;
  std::ofstream(dir / "bad.xml") << "<scene>\n<rigidbodyvertex x=\"0\" y=\"0\" m=\"0\"/>\n</scene>\n";
  const Scene scene = test::control_scene();
  const std::string script = (dir / "steer.yaml").string();
  Result<std::vector<Command>> c = parse_command_script(
      "- {step: 40, spawn: {file: triangle.xml, name: triangle, x: [1.5, 6.0], theta: 0.4}}\n"
      "- {step: 60, delete: body_0}\n"
      "- {step: 70, reset_spawned: true}\n",
      script, scene, kSteps);
  ASSERT_TRUE(c.ok()) << c.error().message;
  ASSERT_EQ(c.value().size(), 3U);
  EXPECT_EQ(c.value()[0].kind, CommandKind::Spawn);
  EXPECT_EQ(c.value()[0].spawn.resource, kFragment);  // the text, kept: the file may change later
  EXPECT_EQ(c.value()[1].entity, "body_0");
  EXPECT_EQ(c.value()[2].kind, CommandKind::ResetSpawned);

  Result<std::vector<Command>> bad =
      parse_command_script("- {step: 1, spawn: {file: bad.xml}}\n", script, scene, kSteps);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("steer.yaml:1:"), std::string::npos) << bad.error().message;
  EXPECT_NE(bad.error().message.find("bad.xml:2:"), std::string::npos) << bad.error().message;
  Result<std::vector<Command>> both = parse_command_script(
      "- {step: 1, spawn: {file: bad.xml, resource: '<scene/>'}}\n", script, scene, kSteps);
  EXPECT_NE(both.error().message.find("give file or resource"), std::string::npos);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace rbsim::control
