// rbsim::testing: golden-log checks for GoogleTest suites, on the same code paths as the command
// line (the run driver and MCAP sink of `rbsim run --record`, the comparer and report of
// `rbsim check`, the verifier of `rbsim check --verify-golden`).
#include "rbsim/testing.hpp"
#include "rbsim/offline_run.hpp"

#include <cstdlib>
#include <filesystem>
#include <optional>

#include "rbsim/atomic_file.hpp"
#include "rbsim/check.hpp"
#include "rbsim/golden.hpp"
#include "rbsim/outputs.hpp"
#include "rbsim/read_file.hpp"
#include "rbsim/run.hpp"
#include "rbsim/scene.hpp"

namespace rbsim::testing {

namespace {

::testing::AssertionResult failure(const std::string& what, const std::string& message) {
  return ::testing::AssertionFailure() << "rbsim::testing::" << what << ": " << message;
}

}  // namespace

::testing::AssertionResult RecordScene(const std::string& scene_path, const std::string& out_mcap,
                                       const RecordOptions& options) {
  if (options.record_every < 1) {
    return failure("RecordScene",
                   "record_every must be >= 1 (got " + std::to_string(options.record_every) + ")");
  }
  control::OfflineRunDef def;
  def.scene = scene_path;
  def.steps = options.steps;
  def.duration = options.duration;
  def.commands = options.commands;
  def.record = {out_mcap, "out_mcap"};
  def.overwrite = options.overwrite;
  def.overwrite_option = "RecordOptions::overwrite";
  def.recording.every = options.record_every;
  def.recording.ns = options.ns;
  if (!options.topics.empty()) {
    std::string list;
    for (const std::string& name : options.topics) list += (list.empty() ? "" : ",") + name;
    Result<msgs::TopicSet> topics = msgs::parse_topic_set(list, options.ns);
    if (!topics) return failure("RecordScene", topics.error().message);
    def.recording.topics = topics.value();
  }
  Result<std::unique_ptr<control::OfflineRun>> run = control::OfflineRun::prepare(def);
  if (!run) return failure("RecordScene", run.error().message);
  Result<PassEnd> end = run.value()->run({});
  if (!end) return failure("RecordScene", end.error().message);
  // A diverged run is never finished: nothing is written (an older file at out_mcap stays).
  if (end.value() == PassEnd::Diverged)
    return failure("RecordScene", describe_divergence(run.value()->driver().divergence()));
  if (Status st = run.value()->finish(); !st) return failure("RecordScene", st.error().message);
  if (Status st = run.value()->finish_commands(); !st) {
    std::string named;
    for (const std::string& m : run.value()->script()->mismatches()) named += "\n  " + m;
    return failure("RecordScene", st.error().message + named);
  }
  return ::testing::AssertionSuccess()
         << "recorded " << run.value()->steps() << " steps of " << scene_path << " to " << out_mcap;
}

::testing::AssertionResult CheckLogs(const std::string& actual_mcap, const std::string& golden_mcap,
                                     const Tolerance& tolerance) {
  check::CheckOptions o;
  o.atol = tolerance.atol;
  o.rtol = tolerance.rtol;
  o.topics = tolerance.topics;
  Result<check::CheckReport> report = check::check_logs(actual_mcap, golden_mcap, o);
  if (!report) return failure("CheckLogs", report.error().message);
  const std::string text = check::format_report(actual_mcap, golden_mcap, o, report.value());
  if (report->passed()) return ::testing::AssertionSuccess() << text;
  return ::testing::AssertionFailure() << text;
}

bool GoldenUpdateRequested() {
  const char* value = std::getenv(kUpdateGoldensVariable);
  return value != nullptr && std::string_view(value) == "1";
}

::testing::AssertionResult UpdateGoldenIfRequested(const std::string& scene_path,
                                                   const std::string& actual_mcap,
                                                   const std::string& golden_mcap,
                                                   const Tolerance& tolerance) {
  const char* what = "UpdateGoldenIfRequested";
  if (!GoldenUpdateRequested()) {
    std::error_code ec;
    if (!std::filesystem::exists(golden_mcap, ec)) {
      return failure(what, "golden " + golden_mcap + " does not exist; run the test with " +
                               kUpdateGoldensVariable + "=1 to create it from " + actual_mcap);
    }
    return CheckLogs(actual_mcap, golden_mcap, tolerance);
  }
  check::GoldenVerifyOptions verify;
  verify.whole_run = false;  // a test records as many steps as it needs
  Result<check::GoldenVerification> verified = check::verify_golden(scene_path, actual_mcap, verify);
  if (!verified) return failure(what, verified.error().message);
  if (!verified->passed) {
    std::string lines;
    for (const std::string& line : verified->lines) lines += "\n  " + line;
    return failure(what, "refusing to write golden " + golden_mcap + ": " + actual_mcap +
                             " fails verification against " + scene_path + lines);
  }
  const Result<Bytes> bytes = read_whole_file(actual_mcap);
  if (!bytes) return failure(what, bytes.error().message);
  AtomicFile out;
  if (Status st = out.open(golden_mcap); !st) return failure(what, st.error().message);
  if (Status st = out.write(bytes->data(), bytes->size()); !st) return failure(what, st.error().message);
  if (Status st = out.commit(); !st) return failure(what, st.error().message);
  return ::testing::AssertionSuccess() << "golden " << golden_mcap << " updated from " << actual_mcap
                                       << " (verified: " << verified->rule << ")";
}

}  // namespace rbsim::testing
