// rbsim run: a scene offline, as fast as possible, into CSV / FOSSSim outputs.
#include <chrono>
#include <cstdio>
#include <memory>
#include <optional>

#include "cli_util.hpp"
#include "commands.hpp"
#include "rbsim/command_script.hpp"
#include "rbsim/control.hpp"
#include "rbsim/csv.hpp"
#include "rbsim/offline_run.hpp"
#include "rbsim/render.hpp"
#include "rbsim/run.hpp"
#include "rbsim/sink.hpp"
#include "validators.hpp"

namespace rbsim::cli {

namespace {

struct RunOptions {
  std::string scene;
  std::optional<std::int64_t> steps;
  std::optional<double> duration;
  std::string csv, energy_csv, fosssim_out, record;
  std::string commands;  // --commands FILE
  std::int64_t record_every = 1;
  std::string compression = "zstd";
  int compression_level = 0;
  std::string ns = "rbsim";
  std::string topics;                                 // --topics LIST
  msgs::TopicSet topic_set = msgs::default_topics();  // what --topics chose
  std::string frames, size = "1280x720";
  double fps = 24.0;
  std::string progress = "auto";
  bool quiet = false;
  bool allow_nonfinite = false;
  bool overwrite = false;
};

int run(const RunOptions& o) {
  // Ctrl-C and SIGTERM only raise a flag from here on, before anything a stop must undo exists
  // (a participant, a listener, an output file): a stop at any stage of start-up ends cleanly.
  install_stop_handlers();
  control::OfflineRunDef def;
  def.scene = o.scene;
  def.steps = o.steps;
  def.duration = o.duration;
  def.commands = o.commands;
  def.csv = {o.csv, "--csv"};
  def.energy_csv = {o.energy_csv, "--energy-csv"};
  def.fosssim_out = {o.fosssim_out, "--fosssim-out"};
  def.record = {o.record, "--record"};
  def.more_outputs = {{o.frames, "--frames", true}};
  def.overwrite = o.overwrite;
  def.recording.every = o.record_every;
  def.recording.ns = o.ns;
  def.recording.topics = o.topic_set;
  if (!o.record.empty()) {
    const Result<mcap::Compression> codec = compression_option(o.compression, o.compression_level);
    if (!codec) return fail("run", codec.error().message);
    def.recording.compression = codec.value();
    def.recording.compression_level = o.compression_level;
  }
  int width = 0, height = 0;
  if (!o.frames.empty()) {
    if (!render::parse_size(o.size, width, height))
      return fail("run", "invalid --size \"" + o.size + "\" (expected WxH)");
    if (!(o.fps > 0.0 && o.fps <= 1000.0)) return fail("run", "--fps must be in (0, 1000]");
  }
  Result<Scene> loaded = load_scene(o.scene);
  if (!loaded) return fail("run", loaded.error().message);
  for (const std::string& w : loaded->warnings) std::fprintf(stderr, "%s\n", w.c_str());
  Result<std::unique_ptr<control::OfflineRun>> prepared =
      control::OfflineRun::prepare(def, std::move(loaded.value()));
  if (!prepared) {
    // A commands script's own mistake is a usage error (its file, line and field named).
    return fail("run", prepared.error().message, prepared.error().code == ErrorCode::InvalidArgument ? 2 : 1);
  }
  control::OfflineRun& offline = *prepared.value();
  const Scene& scene = offline.scene();
  const std::int64_t steps = offline.steps();
  std::unique_ptr<Sink> frames;
  if (!o.frames.empty()) {
    frames = render::make_frame_sink(
        o.frames, width, height, o.fps,
        render::run_duration(steps, scene.world.dt, scene.duration, scene.step_count()), o.overwrite);
    offline.add(*frames);
  }

  Progress progress(steps, o.progress == "always"  ? Progress::Mode::Always
                           : o.progress == "never" ? Progress::Mode::Never
                                                   : Progress::Mode::Auto);
  DriverOptions options;
  options.allow_nonfinite = o.allow_nonfinite;
  options.stop = stop_requested;
  options.progress = [&progress](std::int64_t step) { progress.update(step); };
  const auto start = std::chrono::steady_clock::now();
  const Result<PassEnd> end = offline.run(options);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  progress.finish();
  if (!end) return fail("run", end.error().message);
  if (Status st = offline.finish(); !st) return fail("run", st.error().message);
  const Driver& driver = offline.driver();
  const World& world = driver.world();
  if (end.value() == PassEnd::Diverged) {
    return fail("run", describe_divergence(driver.divergence()) + ". Outputs hold steps 0.." +
                           std::to_string(world.step_index() - 1) + " (--allow-nonfinite keeps going).");
  }

  const std::int64_t done = world.step_index();
  if (!o.quiet) {
    const double rate = wall > 0 ? static_cast<double>(done) / wall : 0.0;
    std::fprintf(
        stderr, "rbsim run: %s: %s, %s, %s (%.6g s simulated) in %s: %.4g steps/s, %.4g body-steps/s\n",
        scene.name.c_str(), count_of(world.body_count(), "body", "bodies").c_str(),
        count_of(world.spring_count(), "spring", "springs").c_str(), count_of(done, "step", "steps").c_str(),
        world.time(), format_seconds(wall).c_str(), rate, rate * world.body_count());
  }
  if (const control::ScriptedRun* script = offline.script()) {
    const Status applied = offline.finish_commands();
    for (const std::string& m : script->mismatches()) std::fprintf(stderr, "rbsim run: %s\n", m.c_str());
    if (const std::optional<std::int64_t> k = script->ended_paused()) {
      std::fprintf(
          stderr,
          "rbsim run: %s left the run paused at step %lld with nothing to resume it: outputs end there\n",
          o.commands.c_str(), static_cast<long long>(*k));
    }
    if (!applied) return fail("run", applied.error().message + "; outputs hold the run");
  }
  if (stop_requested()) {
    std::fprintf(stderr, "rbsim run: interrupted at step %lld of %lld; outputs hold steps 0..%lld\n",
                 static_cast<long long>(done), static_cast<long long>(steps), static_cast<long long>(done));
    return 128 + stop_signal();
  }
  return 0;
}

}  // namespace

Subcommand add_run_command(CLI::App& parent) {
  auto o = std::make_shared<RunOptions>();
  CLI::App* app =
      parent.add_subcommand("run", "Run a scene offline as fast as possible and write its outputs");
  app->add_option("scene", o->scene, "FOSSSim XML scene file")
      ->required();  // the loader reports a missing file (exit 1)
  auto* steps =
      app->add_option("--steps", o->steps, "Number of steps to run (overrides the scene's duration)")
          ->check(non_negative());
  app->add_option("--duration", o->duration,
                  "Simulated seconds to run: ceil(T / dt) steps (overrides the scene)")
      ->check(non_negative())
      ->excludes(steps);
  app->add_option("--csv", o->csv,
                  std::string("Per-body CSV, one row per body per step from step 0: ") + kBodyCsvColumns +
                      " (shortest round-trip decimals: values read back bit-exact)");
  app->add_option("--energy-csv", o->energy_csv,
                  std::string("Scene-wide CSV, one row per step: ") + kEnergyCsvColumns);
  app->add_option("--fosssim-out", o->fosssim_out,
                  "FOSSSim reference binary output (raw little-endian doubles), comparable byte for byte "
                  "with the reference solver's");
  auto* record = app->add_option(
      "--record", o->record,
      "Record the topics (scene description and markers once, then body states, spring states, energy "
      "terms, /tf, springs and /clock per step; --topics chooses) to an MCAP file in the rosbag2 layout (a "
      "path "
      "ending in .mcap), or to a rosbag2 bag directory DIR/ (DIR/metadata.yaml and DIR/DIR_0.mcap, as ROS 2 "
      "Jazzy's recorder writes them) for any other path");
  // Options of one output need that output: given alone they would be silently ignored.
  app->add_option("--record-every", o->record_every, "Record every k-th step (step 0 always)")
      ->check(positive())
      ->needs(record);
  app->add_option("--compression", o->compression, "MCAP chunk compression")
      ->check(CLI::IsMember({"zstd", "lz4", "none"}))
      ->default_str("zstd")
      ->needs(record);
  app->add_option("--compression-level", o->compression_level,
                  "zstd -50..22 or lz4 0..12 (higher: smaller and slower); 0: zstd 1, the MCAP C++ "
                  "library's default")
      ->default_str("0")
      ->needs(record);
  app->add_option("--namespace", o->ns, "ROS namespace of the recorded topics (/<namespace>/body_states ...)")
      ->check(ros_namespace())
      ->default_str("rbsim")
      ->needs(record);
  add_topics_option(app, o->topics, o->ns, o->topic_set, "Topics to record")->needs(record);
  app->add_option(
      "--commands", o->commands,
      "Apply a script of commands at step boundaries (YAML: - {step: 500, set: {forces.1.fx: 2.0}}, "
      "- {t: 1.5, impulse: {body: 3, j: [0, 4], p: [0, 0]}}, pause, steps, resume, reset; see the "
      "README), exactly as a live node applies them; or a recording (FILE.mcap) of a steered session, "
      "re-simulated: its /<ns>/commands at their steps, each with its recorded outcome. Read whole before "
      "step 0; with --record the commands are recorded too");
  auto* frames =
      app->add_option("--frames", o->frames,
                      "Draw PNG frames into this folder during the run, as rbsim render draws them: "
                      "T x fps frames for a run of T = steps x dt (the scene's duration for its full "
                      "length)");
  app->add_option("--fps", o->fps, "Frames per simulated second for --frames")
      ->default_str("24")
      ->needs(frames);
  app->add_option("--size", o->size, "Frame size WxH for --frames")->default_str("1280x720")->needs(frames);
  app->add_flag("--overwrite", o->overwrite,
                "Replace output files that exist, and remove the frame files (frameNNNNN.png, nothing "
                "else) an earlier run or render left in the --frames folder (by default either is refused "
                "before the run starts; the scene itself is never written over)");
  app->add_option("--progress", o->progress,
                  "Progress bar on stderr: auto (on a terminal, runs over 1 s), always, never")
      ->check(CLI::IsMember({"auto", "always", "never"}))
      ->default_str("auto");
  app->add_flag("-q,--quiet", o->quiet, "No closing summary line");
  app->add_flag(
      "--allow-nonfinite", o->allow_nonfinite,
      "Keep going when the state becomes inf/NaN (by default the run stops at the first non-finite value)");
  app->footer(
      "Every output path is checked before step 0 (its folder exists and is writable, it is not a folder, "
      "not the scene, not another output, and it does not exist unless --overwrite). Outputs are written to "
      "a temporary file and renamed into place when complete. Ctrl-C stops the run "
      "cleanly: outputs then hold every step done so far, and the exit status is 130.\n"
      "Exit status: 0 success, 1 error (bad scene, I/O failure, divergence), 2 usage error, 130 "
      "interrupted.");
  return {app, [o] { return run(*o); }};
}

}  // namespace rbsim::cli
