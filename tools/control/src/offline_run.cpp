// One offline run of a scene into its outputs (rbsim/offline_run.hpp).
#include "rbsim/offline_run.hpp"

#include "rbsim/bag.hpp"
#include "rbsim/sink.hpp"

namespace rbsim::control {

namespace {

// The steps a run does: --steps, else ceil(duration / dt), else the scene's.
Result<std::int64_t> resolve_steps(const OfflineRunDef& def, const Scene& scene) {
  std::int64_t steps = scene.step_count();
  if (def.duration) {
    if (!(*def.duration >= 0.0))
      return Error{"duration must be >= 0 (got " + std::to_string(*def.duration) + ")",
                   ErrorCode::InvalidArgument};
    steps = steps_for(*def.duration, scene.world.dt);
  }
  if (def.steps) steps = *def.steps;
  if (steps < 0)
    return Error{"steps must be >= 0 (got " + std::to_string(steps) + ")", ErrorCode::InvalidArgument};
  return steps;
}

// Every output path is checked before step 0: a run never ends by throwing its result away.
Status check_run_outputs(const OfflineRunDef& def) {
  std::vector<std::string> inputs{def.scene};
  if (!def.commands.empty()) inputs.push_back(def.commands);
  std::vector<OutputPath> outputs = {def.csv, def.energy_csv, def.fosssim_out};
  for (const OutputPath& p : def.more_outputs) outputs.push_back(p);
  if (!def.record.path.empty() && recordings::is_bag_output(def.record.path)) {  // a bag directory
    for (OutputPath& p : recordings::bag_outputs(def.record.path, def.record.option))
      outputs.push_back(std::move(p));
  } else {
    outputs.push_back(def.record);
  }
  return check_outputs(outputs, inputs, def.overwrite, def.overwrite_option);
}

}  // namespace

Result<std::unique_ptr<OfflineRun>> OfflineRun::prepare(const OfflineRunDef& def) {
  Result<Scene> loaded = load_scene(def.scene);
  if (!loaded) return loaded.error();
  return prepare(def, std::move(loaded.value()));
}

Result<std::unique_ptr<OfflineRun>> OfflineRun::prepare(const OfflineRunDef& def, Scene scene) {
  Result<std::int64_t> steps = resolve_steps(def, scene);
  if (!steps) return steps.error();
  if (def.recording.every < 1)
    return Error{"record every must be >= 1 (got " + std::to_string(def.recording.every) + ")",
                 ErrorCode::InvalidArgument};
  std::unique_ptr<OfflineRun> run(new OfflineRun(std::move(scene), steps.value()));
  if (Status st = check_run_outputs(def); !st) return st.error();

  // The commands are read whole before step 0: a bad script entry is a usage error naming its line,
  // a recording that lost commands an error naming the first missing one.
  std::vector<ScriptedCommand> commands;
  if (!def.commands.empty()) {
    Result<std::vector<ScriptedCommand>> read = load_commands(def.commands, run->scene_, run->steps_);
    if (!read) return read.error();
    commands = std::move(read.value());
  }
  // The first command that changes the structure, a world load before any other (it asks more of
  // the outputs).
  std::optional<ScriptedCommand> structural;
  for (const ScriptedCommand& c : commands) {
    if (!c.expect_success || !changes_structure(c.command.kind)) continue;
    if (!structural || (replaces_world(c.command.kind) && !replaces_world(structural->command.kind)))
      structural = c;
  }
  Result<Driver> driver = Driver::create(run->scene_);
  if (!driver) return with_context(run->scene_.path + ": ", driver.error());
  run->driver_.emplace(std::move(driver.value()));
  if (!def.commands.empty()) run->script_.emplace(run->scene_, run->steps_, std::move(commands));
  run->commands_ = def.commands;
  if (Status st = run->make_sinks(def, structural); !st) return st.error();
  return run;
}

Status OfflineRun::make_sinks(const OfflineRunDef& def, const std::optional<ScriptedCommand>& structural) {
  std::vector<std::string> paths;
  const auto add = [&](std::unique_ptr<Sink> sink, const std::string& path) {
    sinks_.push_back(std::move(sink));
    paths.push_back(path);
  };
  if (!def.csv.path.empty()) add(make_csv_sink(def.csv.path), def.csv.path);
  if (!def.energy_csv.path.empty()) add(make_energy_csv_sink(def.energy_csv.path), def.energy_csv.path);
  if (!def.fosssim_out.path.empty()) add(make_fosssim_sink(def.fosssim_out.path), def.fosssim_out.path);
  if (!def.record.path.empty()) {
    std::unique_ptr<recordings::McapSink> mcap = recordings::make_mcap_sink(def.record.path, def.recording);
    // A steered run records its commands as the node publishes them (/<ns>/commands), so it can
    // be re-run in turn.
    if (script_) script_->record_to(*mcap);
    add(std::move(mcap), def.record.path);
  }
  // A script that spawns or deletes needs outputs that follow the changed world: refused here,
  // before any output is opened, rather than at its step.
  // A world loaded starts its steps again at 0, which only a recording holds.
  const bool loads = structural && replaces_world(structural->command.kind);
  for (std::size_t k = 0; structural && k < sinks_.size(); ++k) {
    if (loads && paths[k] != def.record.path) {
      return Error{structural->origin + ": " + to_string(structural->command.kind) + ": the output " +
                       paths[k] +
                       " cannot follow a world loaded during the run (its steps start again at 0): record it "
                       "(--record) instead",
                   ErrorCode::InvalidArgument};
    }
    if (sinks_[k]->follows_structure()) continue;
    return Error{structural->origin + ": " + to_string(structural->command.kind) + ": the output " +
                     paths[k] +
                     " cannot follow a world whose bodies change (the per-body and energy CSVs can)",
                 ErrorCode::InvalidArgument};
  }
  for (auto& sink : sinks_) driver_->add(*sink);
  return Ok{};
}

Result<PassEnd> OfflineRun::run(DriverOptions options) {
  options.steps = steps_;
  options.control = script_ ? &script_->controller() : nullptr;
  if (Status st = driver_->begin(); !st) return st.error();
  return driver_->run(options);
}

Status OfflineRun::finish_commands() {
  return script_ ? script_->finish(commands_) : Status(Ok{});
}

}  // namespace rbsim::control
