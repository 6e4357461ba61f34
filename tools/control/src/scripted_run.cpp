// Offline runs steered by loaded commands (rbsim/command_script.hpp): scripts or recordings.
#include <filesystem>
#include <string>
#include <utility>

#include "rbsim/bag.hpp"
#include "rbsim/command_script.hpp"
#include "rbsim/counts.hpp"
#include "rbsim/recording.hpp"

namespace rbsim::control {

Result<std::vector<ScriptedCommand>> load_commands(const std::string& path, const Scene& scene,
                                                   std::int64_t steps) {
  std::vector<ScriptedCommand> out;
  if (!recordings::is_recording(path)) {
    Result<std::vector<Command>> script = load_command_script(path, scene, steps);
    if (!script) return script.error();
    for (Command& c : script.value()) {
      std::string origin = c.source.substr(c.source.find(' ') + 1);  // "script FILE:LINE" -> "FILE:LINE"
      out.push_back({std::move(c), true, std::move(origin)});
    }
    return out;
  }
  recordings::RecordingOptions ro;
  ro.require_scene = false;
  Result<std::unique_ptr<recordings::Recording>> recording = recordings::Recording::open(path, ro);
  if (!recording) return recording.error();
  if (recording.value()->topic(msgs::TopicId::Commands).empty()) {
    return Error{path + ": no commands topic (rbsim_msgs/msg/Command): not a recording of a steered session"};
  }
  Result<std::vector<msgs::CommandMessage>> recorded = recordings::read_commands(*recording.value());
  if (!recorded) return recorded.error();
  std::uint32_t epoch = 0;  // restarts applied so far (resets, world loads), in the node's order
  for (const msgs::CommandMessage& m : recorded.value()) {
    Result<Command> c = from_message(m);
    if (!c) return with_context(path + ": ", c.error());
    const bool reset = restarts_steps(c.value().kind) && m.success;
    out.push_back({std::move(c.value()), m.success, path + ": command " + std::to_string(m.seq), epoch});
    if (reset) ++epoch;
  }
  return out;
}

ScriptedRun::ScriptedRun(const Scene& scene, std::int64_t steps, std::vector<ScriptedCommand> commands)
    : controller_(scene, steps, RunSettings{0.0, 1, false}) {
  controller_.end_when_idle(true);
  submitted_ = commands.size();
  for (ScriptedCommand& s : commands) {
    if (s.epoch >= epochs_.size()) epochs_.resize(s.epoch + 1);
    epochs_[s.epoch].push_back(std::move(s));
  }
  if (!epochs_.empty()) submit_epoch(0);
}

// Submits the commands of epoch `e`; the restart (a reset, a world load) that ends it submits the next one
// from its boundary, where the controller applies those due at once (a resume at step 0 right after it).
void ScriptedRun::submit_epoch(std::size_t e) {
  for (ScriptedCommand& s : epochs_[e]) {
    const bool ends_epoch = restarts_steps(s.command.kind) && s.expect_success && e + 1 < epochs_.size();
    controller_.submit(std::move(s.command), [this, origin = s.origin, expect = s.expect_success, ends_epoch,
                                              e](const CommandResult& r) {
      ++answered_;
      if (ends_epoch && r.successful) submit_epoch(e + 1);
      if (r.successful == expect) return;
      mismatches_.push_back(origin + ": " +
                            (r.successful ? "applied here but refused in the recording" : "refused") + ": " +
                            r.message);
    });
  }
}

void ScriptedRun::record_to(recordings::McapSink& sink) {
  controller_.on_command([this, &sink](const Command& c, const CommandResult& r) {
    cdr_.clear();
    msgs::encode(to_message(c, r, seq_++, controller_.world_info().dt), cdr_);
    if (Status st = sink.record_command(cdr_, r.step); !st && recorded_) recorded_ = st;
  });
}

Status ScriptedRun::finish(const std::string& path) {
  const ControlCounters counted = controller_.counters();
  controller_.close("the run ended");
  if (!recorded_) return recorded_;
  // Commands for steps the run never reached (it ended, or stayed paused before them).
  if (answered_ < submitted_) {
    mismatches_.push_back(std::to_string(submitted_ - answered_) +
                          " of its commands never applied: the run ended before their steps");
  }
  if (mismatches_.empty()) return Ok{};
  return Error{path + ": " + std::to_string(mismatches_.size()) +
               plural(mismatches_.size(), " command", " commands") + " (of " +
               std::to_string(counted.commands) + ") did not apply as " +
               (recordings::is_recording(path) ? "recorded" : "written")};
}

}  // namespace rbsim::control
