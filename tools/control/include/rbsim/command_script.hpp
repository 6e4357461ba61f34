// A script of commands for an offline run (rbsim run SCENE --commands FILE): YAML, one list entry
// per command, applied at step boundaries through the Controller exactly as live commands are.
//
//   - {step: 500, set: {forces.1.fx: 2.0, springs.0.k: 40.0}}     parameters, as one atomic batch
//   - {t: 1.5, impulse: {body: 3, j: [0, 4], p: [0, 0]}}           J (N s, world axes) at p (m, body
//                                                                  frame; optional, default [0, 0])
//   - {step: 600, set_entity_state: {body: 2, x: [1, 0.5], theta: 0, v: [0, 0], omega: 0}}
//                                  the pose (x: m, world frame; theta: rad) and/or the twist (v: m/s;
//                                  omega: rad/s) of a body, each pair whole (SetEntityState)
//   - {step: 900, pause: 0.5}      pause, resuming by itself after 0.5 s of wall time
//   - {step: 900, pause: true}     pause until a later `resume` entry (one must follow)
//   - {step: 900, steps: 5}        while paused: step 5 times, then pause again
//   - {step: 902, stop_stepping: true}   end the `steps` under way there (SimulateSteps' cancel)
//   - {step: 905, resume: true}
//   - {step: 1000, reset: true}    back to step 0 with the run's initial parameters
//   - {step: 200, spawn: {file: crate.xml, name: crate, x: [1, 2], theta: 0.5}}
//                                  a body from a fragment (rbsim/scene.hpp's parse_fragment; `file`
//                                  relative to the script's folder and read now, or its text as
//                                  `resource`), its centre of mass at x, rotated by theta;
//                                  allow_renaming: true takes crate_1, ... when the name was used
//   - {step: 300, delete: crate}   a body by name (a scene's: body_<index>) and its springs
//   - {step: 400, reset_spawned: true}   every spawned body and spring removed
//
// Each entry names its boundary by `step` (an integer in [0, run steps): a command at step k acts
// on the steps after k) or `t` (seconds >= 0: the first step whose time is at or after t, as
// --duration counts steps), not both. Entries of one
// step apply in file order. Values are typed as ROS 2 types parameters (2.0 double, 2 integer,
// true bool; rbsim/ros_args.hpp). Every name, type, range, body and number is checked when the
// file is read, so a bad script is an error naming the file, line and field before step 0;
// pauses change wall time only, never the simulated run.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "rbsim/control.hpp"
#include "rbsim/mcap_sink.hpp"
#include "rbsim/scene.hpp"
#include "rbsim/status.hpp"

namespace rbsim::control {

// The commands of a script, in file order, each with its step set and `source` naming where it
// came from ("script FILE:LINE"). `scene` holds the run's initial parameters; `steps` is its
// length. Errors are "FILE:LINE: FIELD: RULE" (ErrorCode::InvalidArgument), or the read error.
[[nodiscard]] Result<std::vector<Command>> load_command_script(const std::string& path, const Scene& scene,
                                                               std::int64_t steps);
[[nodiscard]] Result<std::vector<Command>> parse_command_script(std::string_view text,
                                                                const std::string& path, const Scene& scene,
                                                                std::int64_t steps);

// A command of an offline run and the outcome it must have: success for a script's, the recorded
// one for a recording's (a command refused live is refused again in a faithful re-run).
struct ScriptedCommand {
  Command command;
  bool expect_success = true;
  std::string origin;  // "steer.yaml:3", "live.mcap: command 4"
  // A recording's: how many resets applied before it. A reset starts the steps again from 0, so
  // a command of a later epoch names a step of the pass that reset began and is submitted once
  // that reset applied (a script's commands are all epoch 0: their steps are the first pass's).
  std::uint32_t epoch = 0;
};
// The commands of `path`: a script (above), or a recording (recordings::is_recording: an MCAP file or a bag
// directory: its
// /<ns>/commands, rbsim/recording.hpp's read_commands, which refuses one that lost a command).
[[nodiscard]] Result<std::vector<ScriptedCommand>> load_commands(const std::string& path, const Scene& scene,
                                                                 std::int64_t steps);

// An offline run steered by loaded commands (rbsim run --commands, rbsim::testing::RecordScene):
// the Controller for the Driver (DriverOptions::control), every command submitted, each applied
// one recorded into the run's MCAP sink when there is one, and those whose outcome differs from
// the expected one collected. A pause that nothing can end ends the run there.
class ScriptedRun {
 public:
  ScriptedRun(const Scene& scene, std::int64_t steps, std::vector<ScriptedCommand> commands);
  Controller& controller() { return controller_; }
  // Every command the controller applies or refuses goes to `sink` as rbsim_msgs/msg/Command.
  void record_to(recordings::McapSink& sink);
  // After the run: closes the controller. The first recording error, or, when commands did not
  // have their outcome, "PATH: N commands (of M) did not apply as written|recorded", each named
  // in mismatches().
  [[nodiscard]] Status finish(const std::string& path);
  const std::vector<std::string>& mismatches() const { return mismatches_; }  // "ORIGIN: refused: MSG"
  std::optional<std::int64_t> ended_paused() const { return controller_.ended_paused(); }

 private:
  void submit_epoch(std::size_t e);

  std::vector<std::vector<ScriptedCommand>> epochs_;  // by ScriptedCommand::epoch
  std::vector<std::string> mismatches_;
  Status recorded_ = Ok{};
  Bytes cdr_;
  std::uint64_t seq_ = 0;
  std::size_t submitted_ = 0, answered_ = 0;
  // Last: destroyed first, so the callbacks it still runs (commands never reached) find the
  // members above alive.
  Controller controller_;
};

}  // namespace rbsim::control
