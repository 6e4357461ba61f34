// Golden logs (rbsim/golden.hpp): the record-every rule, finding a scene's FOSSSim reference
// output, and verify_golden, which reads the golden once (golden_log.cpp) and runs the stages of
// stages.hpp in order, each on the messages of its topics.
#include <filesystem>

#include "golden_log.hpp"
#include "physics.hpp"
#include "rbsim/golden.hpp"
#include "rbsim/read_file.hpp"
#include "stages.hpp"
#include "tally.hpp"

namespace rbsim::check {

namespace fs = std::filesystem;

namespace {

bool same_file_contents(const fs::path& a, const std::string& bytes) {
  std::error_code ec;
  if (fs::file_size(a, ec) != bytes.size() || ec) return false;
  const Result<std::string> other = read_text_file(a.string());
  return other && other.value() == bytes;
}

// The per-step topics every golden has, and the scene description: without them nothing can be
// checked.
bool has_required_topics(const GoldenLog& log, Report& report) {
  using msgs::TopicId;
  for (auto [missing, id] : {std::pair{!log.scene.description, TopicId::SceneDescription},
                             {log.states.messages.empty(), TopicId::BodyStates},
                             {log.springs.messages.empty(), TopicId::SpringStates},
                             {log.energy.messages.empty(), TopicId::Energy}}) {
    if (missing) report.line(false, "recording: no " + std::string(msgs::topic(id).type) + " messages");
  }
  return !report.failed;
}

// Against an independent result: the reference solver's output when the scene has one, else
// energy conservation where it holds; otherwise a note of why neither applies.
Status verify_independent_result(const StageContext& c, const std::string& scene_path, const RecordedRun& run,
                                 const GoldenLog& log) {
  const GoldenVerifyOptions& options = c.options;
  const Scene& scene = c.scene;
  const FosssimMatch match =
      options.fosssim_dir.empty() ? FosssimMatch{} : find_fosssim_reference(scene_path, options.fosssim_dir);
  const char* not_conserved = scene.world.winds.empty() ? "explicit Euler" : "wind";
  if (!match.reference.empty()) {
    return verify_reference(c, match, run, *log.scene.description, log.energy.messages);
  }
  if (scene.world.integrator == Integrator::SymplecticEuler && scene.world.winds.empty()) {
    if (!match.scene.empty())
      c.report.info("the scene is FOSSSim's " + match.scene + ", which has no reference output");
    verify_energy_conservation(c, run);
  } else if (!match.scene.empty()) {
    c.report.info("the scene is FOSSSim's " + match.scene + ", which has no reference output; with " +
                  not_conserved + " energy is not conserved");
  } else {
    c.report.info(std::string("no FOSSSim reference output") +
                  (options.fosssim_dir.empty() ? " (no FOSSSim directory given)" : "") + "; with " +
                  not_conserved + " energy is not conserved");
  }
  return Ok{};
}

}  // namespace

std::int64_t golden_record_every(std::int64_t steps) {
  constexpr std::int64_t kTarget = 500;
  if (steps <= kTarget) return 1;
  const std::int64_t k0 = (steps + kTarget - 1) / kTarget;
  for (std::int64_t k = k0; k <= 2 * k0; ++k) {
    if (steps % k == 0) return k;
  }
  return k0;
}

FosssimMatch find_fosssim_reference(const std::string& scene_path, const std::string& fosssim_dir) {
  FosssimMatch match;
  const Result<std::string> scene = read_text_file(scene_path);
  if (!scene) return match;
  const std::string& bytes = scene.value();
  const fs::path scenes = fs::path(fosssim_dir) / "scenes";
  std::error_code ec;
  std::vector<fs::path> candidates;
  for (fs::recursive_directory_iterator it(scenes, ec), end; !ec && it != end; it.increment(ec)) {
    if (it->is_regular_file(ec) && it->path().extension() == ".xml") candidates.push_back(it->path());
  }
  std::sort(candidates.begin(), candidates.end());
  for (const fs::path& p : candidates) {
    if (!same_file_contents(p, bytes)) continue;
    match.scene = p.string();
    const fs::path rel = p.lexically_relative(scenes);
    for (const char* ext : {".bin.zst", ".bin"}) {
      fs::path ref = fs::path(fosssim_dir) / "reference" / rel.parent_path() / (rel.stem().string() + ext);
      if (fs::is_regular_file(ref, ec)) {
        match.reference = ref.string();
        return match;
      }
    }
    return match;
  }
  return match;
}

Result<std::int64_t> read_record_every(const std::string& golden_path) {
  auto log = read_golden_log(golden_path);
  if (!log) return log.error();
  const auto& t = log->states.messages;
  if (t.empty()) return Error{golden_path + ": no body states recorded"};
  if (t.size() < 2) return std::int64_t{1};
  return static_cast<std::int64_t>(t[1].step - t[0].step);
}

Result<GoldenVerification> verify_golden(const std::string& scene_path, const std::string& golden_path,
                                         const GoldenVerifyOptions& options) {
  Result<Scene> loaded = load_scene(scene_path);
  if (!loaded) return loaded.error();
  const Scene& scene = loaded.value();
  Result<GoldenLog> read = read_golden_log(golden_path);
  if (!read) return read.error();
  const GoldenLog& log = read.value();

  GoldenVerification v;
  Report report{v};
  const Model model = model_of(scene);
  const StageContext context{scene, model, options, report};
  v.steps = scene.step_count();

  // A stage that finds the recording unreadable against this scene ends the verification: the
  // later ones would only repeat its finding.
  if (!has_required_topics(log, report)) return v;
  const msgs::SceneMessage& desc = *log.scene.description;
  if (!verify_scene_description(context, log.scene)) return v;
  std::optional<RecordedRun> run = verify_recorded_steps(context, log);
  if (!run) return v;
  for (const State& s : run->states) run->terms.push_back(terms_of(model, s));

  verify_energy_terms(context, *run, log.energy.messages);
  verify_spring_states(context, *run, log.springs.messages);
  if (!log.poses.messages.empty()) verify_poses(context, *run, log.poses.messages);
  if (!log.tf.messages.empty()) verify_tf(context, *run, log.tf, log.states);
  if (!log.springs_marker.messages.empty())
    verify_springs_marker(context, *run, log.springs_marker.messages, desc);
  verify_markers(context, log.markers, desc, log.states.topic);
  verify_integration(context, *run);
  if (Status st = verify_independent_result(context, scene_path, *run, log); !st) return st.error();
  v.passed = !report.failed && !v.rule.empty();
  return v;
}

}  // namespace rbsim::check
