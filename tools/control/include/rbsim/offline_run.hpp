// One offline run of a scene into its outputs, in stages: the scene loaded, the steps resolved,
// every output checked before step 0, the commands script read whole, the sinks made, then one
// pass of the driver. `rbsim run`, Python's `rbsim.run` and `rbsim::testing::RecordScene` are
// this, each adding only its presentation (and `rbsim run` its frames).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "rbsim/command_script.hpp"
#include "rbsim/mcap_sink.hpp"
#include "rbsim/outputs.hpp"
#include "rbsim/run.hpp"
#include "rbsim/scene.hpp"
#include "rbsim/status.hpp"

namespace rbsim::control {

struct OfflineRunDef {
  std::string scene;                  // the scene file
  std::optional<std::int64_t> steps;  // else ceil(duration / dt), else the scene's own
  std::optional<double> duration;     // simulated seconds
  std::string commands;               // a commands script or a recording to re-simulate
  // Each output's path (empty: not written) and how its caller names it in errors ("--csv").
  OutputPath csv, energy_csv, fosssim_out;
  OutputPath record;                             // an .mcap file, or a bag directory (rbsim/bag.hpp)
  recordings::McapSinkOptions recording;         // how `record` is written
  std::vector<OutputPath> more_outputs;          // checked with the rest (rbsim run's --frames)
  bool overwrite = false;                        // replace outputs that exist
  std::string overwrite_option = "--overwrite";  // how the caller names `overwrite` in errors
};

class OfflineRun {
 public:
  // Held where it was made: the script and the driver keep references to its scene and sinks.
  OfflineRun(const OfflineRun&) = delete;
  OfflineRun& operator=(const OfflineRun&) = delete;

  // Stages up to the pass: errors name the scene, output or script (a script's own mistake has
  // code InvalidArgument, a usage error). Warnings of the scene are in scene().warnings.
  [[nodiscard]] static Result<std::unique_ptr<OfflineRun>> prepare(const OfflineRunDef& def);
  // The same with def.scene already loaded (a caller that reports a scene's errors its own way).
  [[nodiscard]] static Result<std::unique_ptr<OfflineRun>> prepare(const OfflineRunDef& def, Scene scene);

  const Scene& scene() const { return scene_; }
  std::int64_t steps() const { return steps_; }
  Driver& driver() { return *driver_; }
  void add(Sink& sink) { driver_->add(sink); }  // another sink (frames), before run()

  // begin, then one pass of steps() steps with the script's controller. `options` carries the
  // caller's stop, progress and allow_nonfinite; its steps and control are this run's.
  [[nodiscard]] Result<PassEnd> run(DriverOptions options);
  // After run(): the outputs completed and moved into place (a diverged or stopped run's hold the
  // steps before; a caller that wants none of them does not call this, and they are discarded).
  [[nodiscard]] Status finish() { return driver_->finish(); }

  // After run(): the commands' outcome (ScriptedRun::finish), Ok without a script.
  [[nodiscard]] Status finish_commands();
  const ScriptedRun* script() const { return script_ ? &*script_ : nullptr; }

 private:
  OfflineRun(Scene scene, std::int64_t steps) : scene_(std::move(scene)), steps_(steps) {}
  [[nodiscard]] Status make_sinks(const OfflineRunDef& def, const std::optional<ScriptedCommand>& structural);

  Scene scene_;
  std::int64_t steps_ = 0;
  std::string commands_;
  std::optional<Driver> driver_;
  std::vector<std::unique_ptr<Sink>> sinks_;
  std::optional<ScriptedRun> script_;  // after the sinks: its controller reports to the recording
};

}  // namespace rbsim::control
