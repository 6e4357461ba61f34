// rbsim check: compare a recording with a golden one field by field; verify a golden log.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>

#include "cli_util.hpp"
#include "commands.hpp"
#include "rbsim/check.hpp"
#include "rbsim/golden.hpp"
#include "rbsim/scene.hpp"

namespace rbsim::cli {

namespace {

struct CheckArgs {
  std::vector<std::string> files;  // RUN GOLDEN, or SCENE GOLDEN with --verify-golden
  check::CheckOptions options;
  bool all_fields = false;
  bool verify_golden = false;
  std::string fosssim_dir;
  std::string golden_every;  // SCENE
};

constexpr int kMatch = 0, kDiverged = 1, kError = 2;

int compare(const CheckArgs& a) {
  const std::string& run = a.files[0];
  const std::string& golden = a.files[1];
  const auto start = std::chrono::steady_clock::now();
  Result<check::CheckReport> result = check::check_logs(run, golden, a.options);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!result) return fail("check", result.error().message, kError);
  check::ReportFormat format;
  format.all_fields = a.all_fields;
  format.wall_seconds = wall;
  std::fputs(check::format_report(run, golden, a.options, result.value(), format).c_str(), stdout);
  return result->passed() ? kMatch : kDiverged;
}

int verify(const CheckArgs& a) {
  const std::string& scene = a.files[0];
  const std::string& golden = a.files[1];
  check::GoldenVerifyOptions o;
  o.fosssim_dir = a.fosssim_dir;
  Result<check::GoldenVerification> result = check::verify_golden(scene, golden, o);
  if (!result) return fail("check", result.error().message, kError);
  const check::GoldenVerification& v = result.value();
  std::printf("rbsim check --verify-golden %s %s: rule %s\n", scene.c_str(), golden.c_str(),
              v.rule.empty() ? "(none applies)" : v.rule.c_str());
  for (const std::string& line : v.lines) std::printf("  %s\n", line.c_str());
  std::printf("%s\n", v.passed ? "VERIFIED" : "NOT VERIFIED");
  return v.passed ? kMatch : kDiverged;
}

int golden_every(const CheckArgs& a) {
  Result<Scene> scene = load_scene(a.golden_every);
  if (!scene) return fail("check", scene.error().message, kError);
  std::printf("%lld\n", static_cast<long long>(check::golden_record_every(scene->step_count())));
  return kMatch;
}

int check_command(const CheckArgs& a) {
  if (!a.golden_every.empty()) {
    if (!a.files.empty() || a.verify_golden)
      return fail("check", "--golden-every takes no other arguments", kError);
    return golden_every(a);
  }
  if (a.files.size() != 2) {
    return fail("check",
                a.verify_golden ? "--verify-golden needs SCENE and GOLDEN"
                                : "expected two files: RUN.mcap GOLDEN.mcap",
                kError);
  }
  return a.verify_golden ? verify(a) : compare(a);
}

}  // namespace

Subcommand add_check_command(CLI::App& parent) {
  auto a = std::make_shared<CheckArgs>();
  CLI::App* app = parent.add_subcommand(
      "check",
      "Compare a recording with a golden log message by message and field by field (or verify a golden)");
  app->add_option("files", a->files, "RUN.mcap GOLDEN.mcap (with --verify-golden: SCENE.xml GOLDEN.mcap)")
      ->expected(0, 2);
  app->add_option("--atol", a->options.atol,
                  "Absolute tolerance for floating-point fields (default 0: exact)");
  app->add_option("--rtol", a->options.rtol,
                  "Relative tolerance: a float matches when |actual - expected| <= atol + rtol * |expected| "
                  "(default 0: exact)");
  app->add_option(
         "--topics", a->options.topics,
         "Compare only these topics (comma-separated or repeated; /rbsim/body_states or body_states)")
      ->delimiter(',');
  app->add_option("--exclude-topics", a->options.exclude_topics,
                  "Leave these topics out (comma-separated or repeated)")
      ->delimiter(',');
  app->add_flag(
      "--ignore-log-time", [a](std::int64_t) { a->options.compare_log_time = false; },
      "Compare payloads only, not log times (a live recording against rbsim run --record)");
  app->add_flag("--all-fields", a->all_fields, "List every field in the table, also the identical ones");
  app->add_flag(
      "--strict-metadata", a->options.strict_metadata,
      "Make a metadata difference (the scene's name, description, viewport or background, the MCAP "
      "header's profile or library) a divergence; by default it is reported apart and does not fail");
  app->add_flag("--verify-golden", a->verify_golden,
                "Verify GOLDEN.mcap as a golden log of SCENE.xml, independently of the simulator: the scene "
                "description, steps and every energy/spring/pose term recomputed, the dynamics re-integrated "
                "between recorded steps, and the FOSSSim reference output (found by scene contents under "
                "--fosssim-dir) or energy conservation (test/golden/README.md)");
  app->add_option("--fosssim-dir", a->fosssim_dir,
                  "With --verify-golden: FOSSSim scenes and reference outputs (test/data/fosssim)");
  app->add_option(
      "--golden-every", a->golden_every,
      "Print the --record-every K a golden of this scene is recorded with (about 500 steps) and exit");
  app->footer(
      "Per-step messages (body and spring states, energy, /tf, springs, poses, clock) pair up per topic by "
      "simulated step (the step body and spring states and energy carry, round(stamp / dt) for the others "
      "with each file's dt from its scene description); the scene "
      "description, the commands of a steered run (/<ns>/commands) and messages of other types pair up in "
      "order, so a commands mismatch is reported at its command's step, before the states it changed. A step "
      "or message in only one file, a "
      "topic in only one file, a different schema or log time, or a physics value outside the tolerance is "
      "a divergence; steps in one file only are listed per topic with their ranges and likely cause (a "
      "recorder that joined late, another --record-every). Integers, strings, booleans and array lengths "
      "compare exactly. Metadata (scene name, description, viewport, background; a command's source and "
      "message text; MCAP header profile and library) is reported apart and does not fail without "
      "--strict-metadata. Prints the first divergence "
      "(topic, step, field path, expected, actual, difference) and the largest difference per field.\n"
      "Exit status: 0 match (or golden verified), 1 divergence (or verification failed), 2 error "
      "(unreadable, "
      "truncated, corrupted or non-MCAP input, bad arguments).");
  return {app, [a] { return check_command(*a); }};
}

}  // namespace rbsim::cli
