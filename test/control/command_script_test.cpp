// Command scripts (rbsim/command_script.hpp): every action read with its step and origin, errors
// that name the file, line and field before anything runs, and a scripted run that equals the
// same commands given live.
#include "rbsim/command_script.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <future>
#include <string>

#include "control_test_util.hpp"

namespace rbsim::control {
namespace {

using test::Snapshot;
using V = ParameterValue;

constexpr std::int64_t kSteps = 120;  // the control scene: dt 0.01, 2 bodies

std::vector<Command> parse(const std::string& text) {
  const Scene scene = test::control_scene();
  Result<std::vector<Command>> r = parse_command_script(text, "c.yaml", scene, kSteps);
  if (!r) throw std::runtime_error(r.error().message);
  return std::move(r.value());
}

std::string error_of(const std::string& text) {
  const Scene scene = test::control_scene();
  Result<std::vector<Command>> r = parse_command_script(text, "c.yaml", scene, kSteps);
  if (r) return "(no error)";
  EXPECT_EQ(r.error().code, ErrorCode::InvalidArgument) << r.error().message;
  return r.error().message;
}

TEST(ParseCommandScript, ReadsEveryActionWithItsStepAndOrigin) {
  const std::vector<Command> c = parse(
      "- {step: 5, set: {forces.0.fy: -3.7, springs: {1: {k: 40.0}}}}\n"
      "- {t: 0.3, impulse: {body: 1, j: [0.5, -2], p: [0.1, 0]}}\n"
      "- {step: 40, impulse: {body: 0, j: [1.0, 0.0]}}\n"
      "- {step: 50, pause: true}\n"
      "- {step: 50, steps: 5}\n"
      "- {step: 55, resume: true}\n"
      "- {step: 60, pause: 0.25}\n"
      "- {step: 70, reset: yes}\n"
      "- {step: 80, set_entity_state: {body: 1, x: [1, -0.5], theta: 0.25}}\n"
      "- {step: 81, set_entity_state: {body: 0, v: [0.5, 2], omega: -3, x: [0, 0], theta: 1}}\n"
      "- {step: 90, pause: true}\n- {step: 90, steps: 9}\n- {step: 92, stop_stepping: true}\n"
      "- {step: 92, resume: true}\n");
  ASSERT_EQ(c.size(), 14u);
  EXPECT_EQ(c[0].kind, CommandKind::SetParameters);
  EXPECT_EQ(c[0].step, 5);
  EXPECT_TRUE(c[0].atomic);
  ASSERT_EQ(c[0].parameters.size(), 2u);
  EXPECT_EQ(c[0].parameters[0], (Parameter{"forces.0.fy", V::of_double(-3.7)}));
  EXPECT_EQ(c[0].parameters[1], (Parameter{"springs.1.k", V::of_double(40.0)}));  // nested keys join with '.'
  EXPECT_EQ(c[0].source, "script c.yaml:1");
  EXPECT_EQ(c[1].kind, CommandKind::Impulse);
  EXPECT_EQ(c[1].step, steps_for(0.3, 0.01));  // t: the first step at or after it, as --duration
  EXPECT_EQ(c[1].impulse.body, 1);
  EXPECT_EQ(c[1].impulse.impulse, Vec2(0.5, -2.0));
  EXPECT_EQ(c[1].impulse.point, Vec2(0.1, 0.0));
  EXPECT_EQ(c[1].source, "script c.yaml:2");
  EXPECT_EQ(c[2].impulse.point, Vec2(0.0, 0.0));  // p defaults to the centre of mass
  EXPECT_EQ(c[3].kind, CommandKind::Pause);
  EXPECT_EQ(c[3].pause_seconds, 0.0);
  EXPECT_EQ(c[4].kind, CommandKind::Step);
  EXPECT_EQ(c[4].steps, 5);
  EXPECT_EQ(c[5].kind, CommandKind::Resume);
  EXPECT_EQ(c[6].pause_seconds, 0.25);
  EXPECT_EQ(c[7].kind, CommandKind::Reset);
  EXPECT_EQ(c[8].kind, CommandKind::SetState);
  EXPECT_EQ(c[8].state.body, 1);
  EXPECT_TRUE(c[8].state.set_pose);
  EXPECT_FALSE(c[8].state.set_twist);  // a pose alone keeps the velocities
  EXPECT_EQ(c[8].state.position, Vec2(1.0, -0.5));
  EXPECT_EQ(c[8].state.theta, 0.25);
  EXPECT_TRUE(c[9].state.set_pose);
  EXPECT_TRUE(c[9].state.set_twist);
  EXPECT_EQ(c[9].state.velocity, Vec2(0.5, 2.0));
  EXPECT_EQ(c[9].state.omega, -3.0);
  EXPECT_EQ(c[12].kind, CommandKind::StopStepping);
  EXPECT_EQ(c[12].step, 92);
  EXPECT_TRUE(parse("").empty());
}

TEST(ParseCommandScript, ErrorsNameTheFileLineAndField) {
  const std::string ok = "- {step: 1, resume: true}\n";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"step: 1", "c.yaml:1: expected a list of commands"},
      {"- [1, 2]", "c.yaml:1: entry: must be a map"},
      {ok + "- {set: {forces.0.fy: 1.0}}", "c.yaml:2: step: each entry needs step: N or t: SECONDS"},
      {ok + "- {step: 1, t: 0.5, resume: true}", "c.yaml:2: t: give step or t, not both"},
      {ok + "- {step: 1.5, resume: true}", "c.yaml:2: step: must be an integer"},
      {ok + "- {step: 120, resume: true}", "c.yaml:2: step: step 120 is outside the run"},
      {ok + "- {step: -1, resume: true}", "c.yaml:2: step: step -1 is outside the run"},
      {ok + "- {t: .nan, resume: true}", "c.yaml:2: t: must be a finite number of seconds >= 0"},
      {ok + "- {step: 1}", "c.yaml:2: action: missing"},
      {ok + "- {step: 1, resume: true, reset: true}", "c.yaml:2: reset: one action per entry"},
      {ok + "- {step: 1, jump: 3}", "c.yaml:2: jump: unknown field"},
      {ok + "- {step: 1,\n   set: {forces.9.fy: 1.0}}",
       "c.yaml:3: set.forces.9.fy: parameter 'forces.9.fy' is not declared"},
      {ok + "- {step: 1, set: {forces.0.fy: 1}}", "c.yaml:2: set.forces.0.fy: Wrong parameter type"},
      {ok + "- {step: 1, set: {dt: 0.5}}",
       "c.yaml:2: set.dt: parameter 'dt' cannot be set because it is read-only"},
      {ok + "- {step: 1, set: {springs.0.k: -.inf}}",
       "c.yaml:2: set.springs.0.k: Parameter {springs.0.k} must be finite"},
      {ok + "- {step: 1, set: {}}", "c.yaml:2: set: must be a map of parameters"},
      {ok + "- {step: 1, impulse: {body: 2, j: [0, 1]}}",
       "c.yaml:2: impulse.body: must be a body index in [0, 2)"},
      {ok + "- {step: 1, impulse: {body: 0}}", "c.yaml:2: impulse.j: missing"},
      {ok + "- {step: 1, impulse: {body: 0, j: [0, .inf]}}",
       "c.yaml:2: impulse.j: must be two finite numbers"},
      {ok + "- {step: 1, impulse: {body: 0, j: [0]}}", "c.yaml:2: impulse.j: must be [x, y]"},
      {ok + "- {step: 1, impulse: {body: 0, j: [0, 1], q: 1}}", "c.yaml:2: impulse.q: unknown field"},
      {ok + "- {step: 1, set_entity_state: {body: 2, x: [0, 0], theta: 0}}",
       "c.yaml:2: set_entity_state.body: must be a body index in [0, 2)"},
      {ok + "- {step: 1, set_entity_state: {body: 0, x: [0, 0]}}",
       "c.yaml:2: set_entity_state.theta: missing (give x and theta together)"},
      {ok + "- {step: 1, set_entity_state: {body: 0, omega: 1}}",
       "c.yaml:2: set_entity_state.v: missing (give v and omega together)"},
      {ok + "- {step: 1, set_entity_state: {body: 0, v: [0, 1], omega: .nan}}",
       "c.yaml:2: set_entity_state.omega: must be a finite number"},
      {ok + "- {step: 1, set_entity_state: {body: 0}}", "c.yaml:2: set_entity_state: sets nothing"},
      {ok + "- {step: 1, set_entity_state: {body: 0, a: [0, 1]}}",
       "c.yaml:2: set_entity_state.a: unknown field"},
      {ok + "- {step: 1, stop_stepping: 1}", "c.yaml:2: stop_stepping: must be true"},
      // A stop_stepping drops the steps still to take: the run stays paused where it stopped.
      {ok + "- {step: 20, pause: true}\n- {step: 20, steps: 5}\n- {step: 22, stop_stepping: true}\n"
            "- {step: 25, resume: true}",
       "c.yaml:2: pause: no resume follows at or before step 22"},
      {ok + "- {step: 1, pause: -2}",
       "c.yaml:2: pause: must be true (until a resume) or wall-clock seconds > 0"},
      {ok + "- {step: 1, resume: false}", "c.yaml:2: resume: must be true"},
      {ok + "- {step: 1, steps: 0}", "c.yaml:2: steps: must be an integer >= 1"},
      {ok + "- {step: 3, steps: 2}", "c.yaml:2: steps: only while paused"},
      {ok + "- {step: 9, pause: true}\n- {step: 8, resume: true}", "c.yaml:2: pause: no resume follows"},
      // The fuzzer's hang: steps 20..23 while paused, a reset at 30 never reached.
      {ok + "- {step: 20, pause: true}\n- {step: 20, steps: 3}\n- {step: 30, reset: true}",
       "c.yaml:2: pause: no resume follows at or before step 23"},
      {ok + "- {step: 20, pause: true}\n- {step: 20, steps: 3}\n- {step: 23, resume: true}\n- {step: 24, "
            "steps: 1}",
       "c.yaml:5: steps: only while paused"},
      {ok + "- {step: 1, set: {forces.0.fy: [1.0, }", "c.yaml:2: not valid YAML"},
  };
  for (const auto& [text, want] : cases) {
    EXPECT_NE(error_of(text).find(want), std::string::npos) << text << "\n -> " << error_of(text);
  }
}

TEST(LoadCommandScript, NamesAFileItCannotRead) {
  const Scene scene = test::control_scene();
  Result<std::vector<Command>> r = load_command_script("/nonexistent/c.yaml", scene, kSteps);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::IoError);
  EXPECT_NE(r.error().message.find("/nonexistent/c.yaml"), std::string::npos) << r.error().message;
}

// A script's commands through the Controller: the run equals the same commands submitted one by
// one (as a live session gives them), pauses included, and differs from the run without them
// from the first step after the first change.
TEST(ParseCommandScript, AScriptedRunEqualsTheSameCommandsGivenLive) {
  const Scene scene = test::control_scene();
  const std::vector<Command> script = parse(
      "- {step: 30, set: {forces.0.fy: -3.7}}\n"
      "- {step: 50, pause: true}\n"
      "- {step: 50, steps: 4}\n"
      "- {step: 54, impulse: {body: 1, j: [0.5, 2.0], p: [0.1, 0.0]}}\n"
      "- {step: 54, resume: true}\n"
      "- {step: 60, set_entity_state: {body: 0, v: [0.25, -1], omega: 0.5}}\n"
      "- {step: 70, pause: true}\n"
      "- {step: 70, steps: 20}\n"
      "- {step: 73, stop_stepping: true}\n"
      "- {step: 73, resume: true}\n"
      "- {step: 80, pause: 0.05}\n");
  Controller scripted(scene, kSteps, RunSettings{0.0, 1, false});
  for (const Command& c : script) scripted.submit(c, nullptr);
  const auto start = std::chrono::steady_clock::now();
  const std::vector<Snapshot> run = test::run(scene, kSteps, &scripted);
  EXPECT_GE(std::chrono::steady_clock::now() - start, std::chrono::milliseconds(50));  // the timed pause
  EXPECT_EQ(scripted.counters().commands, 12u);  // eleven and the timed pause's own resume
  EXPECT_FALSE(scripted.settings().paused);

  Controller live(scene, kSteps, RunSettings{0.0, 1, false});
  Command set;
  set.step = 30;
  set.kind = CommandKind::SetParameters;
  set.parameters = {{"forces.0.fy", V::of_double(-3.7)}};
  Command kick;
  kick.step = 54;
  kick.kind = CommandKind::Impulse;
  kick.impulse = ImpulseArgs{1, Vec2(0.5, 2.0), Vec2(0.1, 0.0)};
  Command state;  // the stepping 70..73 leaves no trace in the states: only wall time differs
  state.step = 60;
  state.kind = CommandKind::SetState;
  state.state.body = 0;
  state.state.set_twist = true;
  state.state.velocity = Vec2(0.25, -1.0);
  state.state.omega = 0.5;
  live.submit(set, nullptr);
  live.submit(kick, nullptr);
  live.submit(state, nullptr);
  const std::vector<Snapshot> given = test::run(scene, kSteps, &live);
  ASSERT_EQ(run.size(), given.size());
  for (std::size_t i = 0; i < run.size(); ++i)
    EXPECT_TRUE(test::same_bits(run[i].state, given[i].state)) << i;

  const std::vector<Snapshot> plain = test::run(scene, kSteps);
  EXPECT_TRUE(test::same_bits(run[30].state, plain[30].state));
  EXPECT_FALSE(test::same_bits(run[31].state, plain[31].state));
}

// A recorded session with a reset: the commands after it (a later epoch) name steps of the pass
// the reset began, so they apply after it even where their steps are lower than its own (as
// STOPPED then PLAYING records pause@30, reset@30, resume@0), at the reset's own boundary for step
// 0. The run is the first pass to the reset and then a pass with the later commands alone.
TEST(ScriptedRun, CommandsAfterAResetApplyInThePassItBegins) {
  const Scene scene = test::control_scene();
  const auto command = [](std::int64_t step, CommandKind kind, std::uint32_t epoch) {
    ScriptedCommand s;
    s.command.step = step;
    s.command.kind = kind;
    s.epoch = epoch;
    s.origin = "command at " + std::to_string(step);
    return s;
  };
  std::vector<ScriptedCommand> session;
  session.push_back(command(20, CommandKind::Impulse, 0));
  session.back().command.impulse = ImpulseArgs{1, Vec2(0.5, 2.0), Vec2(0.0, 0.0)};
  session.push_back(command(30, CommandKind::Pause, 0));
  session.push_back(command(30, CommandKind::Reset, 0));
  session.push_back(command(0, CommandKind::Resume, 1));
  session.push_back(command(10, CommandKind::Impulse, 1));
  session.back().command.impulse = ImpulseArgs{0, Vec2(-1.0, 0.25), Vec2(0.0, 0.0)};
  ScriptedRun scripted(scene, kSteps, session);
  const std::vector<Snapshot> run = test::run(scene, kSteps, &scripted.controller());
  EXPECT_TRUE(scripted.finish("session").ok())
      << (scripted.mismatches().empty() ? "" : scripted.mismatches()[0]);
  EXPECT_FALSE(scripted.ended_paused());

  // The two passes, each by itself.
  Controller first(scene, kSteps, RunSettings{0.0, 1, false});
  Command kick;
  kick.step = 20;
  kick.kind = CommandKind::Impulse;
  kick.impulse = session[0].command.impulse;
  first.submit(kick, nullptr);
  const std::vector<Snapshot> a = test::run(scene, kSteps, &first);
  Controller second(scene, kSteps, RunSettings{0.0, 1, false});
  kick.step = 10;
  kick.impulse = session[4].command.impulse;
  second.submit(kick, nullptr);
  const std::vector<Snapshot> b = test::run(scene, kSteps, &second);

  const auto back = std::adjacent_find(run.begin(), run.end(),
                                       [](const Snapshot& x, const Snapshot& y) { return y.step < x.step; });
  ASSERT_NE(back, run.end()) << "no reset in the run";
  const std::size_t reset_at = static_cast<std::size_t>(back - run.begin()) + 1;
  ASSERT_EQ(run[reset_at - 1].step, 30);
  for (std::size_t i = 0; i < reset_at; ++i) EXPECT_TRUE(test::same_bits(run[i].state, a[i].state)) << i;
  // After the reset, every step the sinks were given up to the run's end, each equal to that
  // step of the second pass alone.
  EXPECT_EQ(run.back().step, kSteps);
  EXPECT_GE(run.size() - reset_at, static_cast<std::size_t>(kSteps));
  for (std::size_t i = reset_at; i < run.size(); ++i) {
    const auto k = static_cast<std::size_t>(run[i].step);
    ASSERT_LT(k, b.size());
    ASSERT_EQ(b[k].step, run[i].step);
    EXPECT_TRUE(test::same_bits(run[i].state, b[k].state)) << "second pass, step " << k;
  }
}

// Commands as rbsim_msgs/msg/Command and back: every kind keeps what a re-run applies.
TEST(CommandMessage, ToMessageAndBackKeepsEveryCommand) {
  const std::vector<Command> script = parse(
      "- {step: 5, set: {forces.0.fy: -3.7, springs.0.k: 40.0}}\n"
      "- {step: 7, impulse: {body: 1, j: [0.5, -2], p: [0.1, 0]}}\n"
      "- {step: 9, pause: true}\n- {step: 9, steps: 3}\n- {step: 12, resume: true}\n"
      "- {step: 20, pause: 0.5}\n- {step: 30, reset: true}\n");
  std::uint64_t seq = 0;
  for (const Command& c : script) {
    CommandResult r;
    r.successful = true;
    r.step = c.step;
    r.message = "done";
    const msgs::CommandMessage m = to_message(c, r, seq, 0.01);
    EXPECT_EQ(m.seq, seq++);
    EXPECT_EQ(m.stamp.sec, 0);
    EXPECT_EQ(m.stamp.nanosec, static_cast<std::uint32_t>(c.step) * 10000000u);
    Bytes cdr;
    msgs::encode(m, cdr);
    msgs::CommandMessage decoded;
    ASSERT_TRUE(msgs::decode(cdr, decoded).ok());
    Result<Command> back = from_message(decoded);
    ASSERT_TRUE(back) << back.error().message;
    EXPECT_EQ(back->step, c.step);
    EXPECT_EQ(back->kind, c.kind);
    EXPECT_EQ(back->parameters, c.parameters);
    EXPECT_EQ(back->atomic, c.atomic);
    EXPECT_EQ(back->steps, c.steps);
    EXPECT_EQ(back->pause_seconds, c.pause_seconds);
    EXPECT_EQ(back->impulse.body, c.impulse.body);
    EXPECT_EQ(back->impulse.impulse, c.impulse.impulse);
    EXPECT_EQ(back->impulse.point, c.impulse.point);
    EXPECT_EQ(back->source, c.source);
  }
  // stop_stepping (a SimulateSteps cancel): kind 7, no arguments.
  Command stop;
  stop.step = 40;
  stop.kind = CommandKind::StopStepping;
  stop.source = "ros2 action simulate_steps cancel";
  CommandResult stopped;
  stopped.successful = true;
  stopped.step = 40;
  const msgs::CommandMessage sm = to_message(stop, stopped, 9, 0.01);
  EXPECT_EQ(sm.kind, msgs::CommandMessage::StopStepping);
  Result<Command> stop_back = from_message(sm);
  ASSERT_TRUE(stop_back) << stop_back.error().message;
  EXPECT_EQ(stop_back->kind, CommandKind::StopStepping);
  EXPECT_EQ(stop_back->step, 40);
  msgs::CommandMessage bad;
  bad.seq = 4;
  bad.kind = 13;
  Result<Command> refused = from_message(bad);
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().message.find("command 4: unknown kind 13"), std::string::npos)
      << refused.error().message;
}

// set_entity_state (simulation_interfaces' SetEntityState) as a message: its values as named
// float64 parameters beside the body, a pose or a twist whole; anything else is refused naming the
// command.
TEST(CommandMessage, SetStateTravelsAsNamedParameters) {
  Command c;
  c.step = 12;
  c.kind = CommandKind::SetState;
  c.state.body = 3;
  c.state.set_twist = true;
  c.state.velocity = Vec2(-0.25, 1e-300);
  c.state.omega = 4.5;
  CommandResult r;
  r.successful = true;
  r.step = 12;
  msgs::CommandMessage m = to_message(c, r, 0, 0.01);
  EXPECT_EQ(m.kind, msgs::CommandMessage::SetEntityState);
  EXPECT_EQ(m.body, 3u);
  ASSERT_EQ(m.parameters.size(), 3u);
  EXPECT_EQ(m.parameters[0].name, "vx");
  EXPECT_EQ(m.parameters[2].value, ParameterValue::of_double(4.5));
  Result<Command> back = from_message(m);
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_EQ(back->kind, CommandKind::SetState);
  EXPECT_EQ(back->state.body, 3);
  EXPECT_FALSE(back->state.set_pose);
  EXPECT_TRUE(back->state.set_twist);
  EXPECT_EQ(back->state.velocity, c.state.velocity);
  EXPECT_EQ(back->state.omega, 4.5);
  EXPECT_TRUE(back->parameters.empty());

  c.state.set_pose = true;
  c.state.position = Vec2(1.0, 2.0);
  c.state.theta = -0.5;
  m = to_message(c, r, 1, 0.01);
  ASSERT_EQ(m.parameters.size(), 6u);
  back = from_message(m);
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_TRUE(back->state.set_pose);
  EXPECT_EQ(back->state.position, c.state.position);
  EXPECT_EQ(back->state.theta, -0.5);

  for (const auto& [params, rule] : std::vector<std::pair<std::vector<Parameter>, std::string>>{
           {{{"x", ParameterValue::of_double(1)}}, "together"},
           {{{"mass", ParameterValue::of_double(1)}}, "none of x, y, theta"},
           {{{"x", ParameterValue::of_integer(1)}}, "not a double"}}) {
    msgs::CommandMessage wrong = m;
    wrong.seq = 9;
    wrong.parameters = params;
    Result<Command> no = from_message(wrong);
    ASSERT_FALSE(no) << rule;
    EXPECT_NE(no.error().message.find("command 9: set_entity_state"), std::string::npos)
        << no.error().message;
    EXPECT_NE(no.error().message.find(rule), std::string::npos) << no.error().message;
  }
}

}  // namespace
}  // namespace rbsim::control
