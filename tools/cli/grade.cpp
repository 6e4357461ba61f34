// rbsim grade: check a scene against the FOSSSim reference solver's output, as its grader does.
#include <cstdio>
#include <memory>

#include "cli_util.hpp"
#include "commands.hpp"
#include "rbsim/fosssim.hpp"

namespace rbsim::cli {

namespace {
struct GradeArgs {
  std::string scene, reference;
};

int grade_command(const GradeArgs& a) {
  Result<Scene> scene = load_scene(a.scene);
  if (!scene) return fail("grade", scene.error().message, 2);
  Result<std::vector<std::byte>> bytes = read_file(a.reference);
  if (!bytes) return fail("grade", bytes.error().message, 2);
  Result<FosssimLog> log =
      parse_fosssim(bytes.value(), static_cast<std::int32_t>(scene->world.bodies.size()));
  if (!log) return fail("grade", a.reference + ": " + log.error().message, 2);
  Result<GradeReport> report = grade(scene.value(), log.value());
  if (!report) return fail("grade", report.error().message, 2);
  const GradeReport& r = report.value();
  std::printf(
      "%s: %s  steps %lld  max step diff %.3g (step %lld)  summed %.3g  max quantity diff %.3g (%s)\n",
      scene->name.c_str(), r.passed ? "PASS" : "FAIL", static_cast<long long>(r.steps), r.max_step_diff,
      static_cast<long long>(r.worst_step), r.sum_step_diff, r.max_quantity_diff,
      r.worst_quantity.empty() ? "-" : r.worst_quantity.c_str());
  if (!r.passed) std::printf("  %s\n", r.message.c_str());
  return r.passed ? 0 : 1;
}
}  // namespace

Subcommand add_grade_command(CLI::App& parent) {
  auto a = std::make_shared<GradeArgs>();
  CLI::App* app = parent.add_subcommand(
      "grade",
      "Grade a scene against a FOSSSim reference output the way the reference does: per step, load the "
      "reference state, check the quantities, step once, compare with the next reference state");
  app->add_option("scene", a->scene, "FOSSSim XML scene file")
      ->required();  // missing files are errors (exit 2)
  app->add_option("reference", a->reference, "Reference output (.bin, or .bin.zst)")->required();
  app->footer(
      "Passes when the largest per-step state difference is < 1e-8, their sum < 1e-6, and every quantity "
      "(M, X, I, P, L_point, L_spin, T_point, T_spin, U) is within 1e-8.\n"
      "Exit status: 0 pass, 1 fail, 2 error or usage error.");
  return {app, [a] { return grade_command(*a); }};
}

}  // namespace rbsim::cli
