// Golden logs: every bundled scene rerun and checked against its golden with `rbsim check`, the
// goldens re-verified independently of the simulator, and the check itself exercised: perturbed
// runs, topic selection, tolerances, missing/extra messages, bad input, scripts/golden.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>

#include "rbsim/check.hpp"
#include "rbsim/golden.hpp"
#include "rbsim/mcap_sink.hpp"
#include "rbsim/subprocess.hpp"
#include "rbsim/test_bytes.hpp"

namespace {

namespace fs = std::filesystem;
using namespace rbsim;

const fs::path kSource = RBSIM_SOURCE_DIR;
const fs::path kScenes = RBSIM_SCENES_DIR;
const fs::path kGoldens = RBSIM_GOLDEN_DIR;
const fs::path kFosssim = RBSIM_FOSSSIM_DIR;
constexpr std::uintmax_t kMaxGoldenBytes = 2u << 20;
constexpr std::uintmax_t kMaxGoldenTotal = 6u << 20;

// ---------------------------------------------------------------------------------------------
// Helpers: files, temporary directories and child processes come from test/support.

using test::Outcome;
using test::read_text;
using test::TempDir;
using test::write_text;

Outcome run_process(const std::string& exe, const std::vector<std::string>& args,
                    const std::vector<std::string>& extra_env = {}) {
  return test::run_process(exe, args, std::chrono::seconds(240), extra_env);
}

Outcome rbsim(const std::vector<std::string>& args) {
  return run_process(RBSIM_EXE, args);
}

// Records `scene` to `out` (all topics, zstd) with the given extra options; asserts success.
void record(const fs::path& scene, const fs::path& out, const std::vector<std::string>& extra) {
  std::vector<std::string> args{"run",        scene.string(), "--record", out.string(),
                                "--progress", "never",        "--quiet"};
  args.insert(args.end(), extra.begin(), extra.end());
  const Outcome o = rbsim(args);
  ASSERT_EQ(o.exit_code, 0) << o;
}

// A copy of `scene` with `from` replaced by `to` (exactly once), under `dir` with the same file
// name (the recorded scene name is the file stem, so only the edited value differs).
fs::path edited(const fs::path& dir, const fs::path& scene, const std::string& from, const std::string& to) {
  std::string text = read_text(scene);
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from << " not in " << scene;
  EXPECT_EQ(text.find(from, at + 1), std::string::npos) << from << " more than once in " << scene;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  const fs::path out = dir / scene.filename();
  write_text(out, text);
  return out;
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// Scenes under scenes/ (subfolders included), as paths relative to it without ".xml".
std::vector<std::string> scene_names() {
  std::vector<std::string> names;
  std::error_code ec;
  for (fs::recursive_directory_iterator it(kScenes, ec), end; !ec && it != end; it.increment(ec)) {
    if (it->is_regular_file() && it->path().extension() == ".xml") {
      names.push_back(it->path().lexically_relative(kScenes).replace_extension().generic_string());
    }
  }
  std::sort(names.begin(), names.end());
  return names;
}

fs::path scene_path(const std::string& name) {
  return kScenes / (name + ".xml");
}
fs::path golden_path(const std::string& name) {
  return kGoldens / (name + ".mcap");
}

std::string to_string(const check::GoldenVerification& v) {
  std::string s = "rule " + v.rule + "\n";
  for (const std::string& line : v.lines) s += "  " + line + "\n";
  return s;
}

// ---------------------------------------------------------------------------------------------
// Every scene: rerun and check against its golden; the golden verified; its size.

class GoldenScene : public testing::TestWithParam<std::string> {};

TEST_P(GoldenScene, RerunMatchesGolden) {
  const fs::path golden = golden_path(GetParam());
  ASSERT_TRUE(fs::exists(golden)) << "no golden for " << scene_path(GetParam()) << ": run scripts/golden "
                                  << scene_path(GetParam());
  Result<std::int64_t> every = check::read_record_every(golden.string());
  ASSERT_TRUE(every) << every.error().message;
  TempDir tmp;
  const fs::path run = tmp / "run.mcap";
  record(scene_path(GetParam()), run, {"--record-every", std::to_string(every.value())});
  const Outcome o = rbsim({"check", run.string(), golden.string()});
  EXPECT_EQ(o.exit_code, 0) << o;
  EXPECT_TRUE(contains(o.out, ": MATCH")) << o;
  EXPECT_FALSE(contains(o.out, "first divergence")) << o;
}

TEST_P(GoldenScene, GoldenIsVerified) {
  const fs::path golden = golden_path(GetParam());
  ASSERT_TRUE(fs::exists(golden)) << "no golden for " << scene_path(GetParam());
  check::GoldenVerifyOptions options;
  options.fosssim_dir = kFosssim.string();
  Result<check::GoldenVerification> v =
      check::verify_golden(scene_path(GetParam()).string(), golden.string(), options);
  ASSERT_TRUE(v) << v.error().message;
  EXPECT_TRUE(v->passed) << to_string(v.value());
  // Every golden is re-integrated independently; against the FOSSSim reference when there is one,
  // else, for conservative symplectic scenes, checked for energy conservation.
  const check::FosssimMatch match =
      check::find_fosssim_reference(scene_path(GetParam()).string(), kFosssim.string());
  Result<Scene> scene = load_scene(scene_path(GetParam()).string());
  ASSERT_TRUE(scene) << scene.error().message;
  const bool conservative = scene->world.integrator == Integrator::SymplecticEuler &&
                            scene->world.winds.empty() && match.reference.empty();
  EXPECT_TRUE(contains(v->rule, "independent-integration")) << to_string(v.value());
  EXPECT_EQ(contains(v->rule, "fosssim-reference"), !match.reference.empty()) << to_string(v.value());
  EXPECT_EQ(contains(v->rule, "symplectic-energy"), conservative) << to_string(v.value());
  // A golden covers its whole run: steps 0, K, 2K, ... up to the scene's last step.
  EXPECT_GT(v->record_every, 0);
  EXPECT_LT(v->steps - v->last_step, v->record_every);
}

TEST_P(GoldenScene, GoldenIsSmall) {
  const fs::path golden = golden_path(GetParam());
  ASSERT_TRUE(fs::exists(golden));
  EXPECT_LE(fs::file_size(golden), kMaxGoldenBytes);
}

INSTANTIATE_TEST_SUITE_P(Scenes, GoldenScene, testing::ValuesIn(scene_names()),
                         [](const testing::TestParamInfo<std::string>& param_info) {
                           std::string name = param_info.param;
                           for (char& c : name) {
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           }
                           return name;
                         });

TEST(GoldenDir, OneGoldenPerSceneAndSmallInTotal) {
  const std::vector<std::string> scenes = scene_names();
  ASSERT_FALSE(scenes.empty());
  std::set<std::string> goldens;
  std::uintmax_t total = 0;
  for (fs::recursive_directory_iterator it(kGoldens), end; it != end; ++it) {
    if (it->is_regular_file() && it->path().extension() == ".mcap") {
      goldens.insert(it->path().lexically_relative(kGoldens).replace_extension().generic_string());
      total += it->file_size();
    }
  }
  EXPECT_EQ(goldens, std::set<std::string>(scenes.begin(), scenes.end()))
      << "every scene in scenes/ needs test/golden/<name>.mcap (scripts/golden), and no golden may outlive "
         "its scene";
  EXPECT_LE(total, kMaxGoldenTotal);
}

// ---------------------------------------------------------------------------------------------
// rbsim check

const fs::path kChain = kScenes / "chain.xml";
const fs::path kCantilever = kScenes / "cantilever.xml";
const fs::path kChainGolden = kGoldens / "chain.mcap";
constexpr const char* kChainEvery = "200";  // chain's golden: --record-every 200 (checked below)

TEST(Check, ChainGoldenIsRecordedEvery200Steps) {
  Result<std::int64_t> every = check::read_record_every(kChainGolden.string());
  ASSERT_TRUE(every) << every.error().message;
  EXPECT_EQ(std::to_string(every.value()), kChainEvery);
}

TEST(Check, IdenticalFilesMatch) {
  Outcome o = rbsim({"check", kChainGolden.string(), kChainGolden.string()});
  EXPECT_EQ(o.exit_code, 0) << o;
  EXPECT_TRUE(contains(o.out, ": MATCH")) << o;
  EXPECT_TRUE(contains(o.out, "fields identical")) << o;
  TempDir tmp;
  fs::copy_file(kChainGolden, tmp / "copy.mcap");
  o = rbsim({"check", (tmp / "copy.mcap").string(), kChainGolden.string(), "--all-fields"});
  EXPECT_EQ(o.exit_code, 0) << o;
  EXPECT_TRUE(std::regex_search(o.out, std::regex(R"(/rbsim/body_states +bodies\[\]\.x +float)")))
      << o;  // all fields
}

TEST(Check, ChangedTimeStepDivergesAtTheSceneDescription) {
  TempDir tmp;
  const fs::path scene = edited(tmp.path(), kChain, "dt=\"0.001\"", "dt=\"0.0009\"");
  const fs::path run = tmp / "run.mcap";
  record(scene, run, {"--record-every", kChainEvery});
  Outcome o = rbsim({"check", run.string(), kChainGolden.string()});
  EXPECT_EQ(o.exit_code, 1) << o;
  EXPECT_TRUE(contains(o.out, ": DIVERGED")) << o;
  EXPECT_TRUE(contains(o.out,
                       "first divergence: topic /rbsim/scene, message 0, field dt: expected 0.001, actual "
                       "0.0009, difference -0.0001"))
      << o;
  // Without the scene description, the first difference is the stamp of the first step recorded.
  o = rbsim({"check", run.string(), kChainGolden.string(), "--exclude-topics", "/rbsim/scene"});
  EXPECT_EQ(o.exit_code, 1) << o;
  EXPECT_TRUE(contains(o.out,
                       "first divergence: topic /rbsim/body_states, step 200, field header.stamp.nanosec: "
                       "expected 200000000, actual 180000000, difference -20000000"))
      << o;
  EXPECT_TRUE(contains(o.out, "/rbsim/body_states")) << o;  // in the per-field table
}

TEST(Check, ChangedMassDivergesInTheBodyStates) {
  // The first vertex of body 0 gets half as much mass again: M, I and the centre of mass move.
  TempDir tmp;
  const fs::path scene = edited(tmp.path(), kChain, "<rigidbodyvertex x=\"0\" y=\"0\" m=\"1\"/>",
                                "<rigidbodyvertex x=\"0\" y=\"0\" m=\"1.5\"/>");
  const fs::path run = tmp / "run.mcap";
  record(scene, run, {"--record-every", kChainEvery});
  Outcome o = rbsim({"check", run.string(), kChainGolden.string()});
  EXPECT_EQ(o.exit_code, 1) << o;
  EXPECT_TRUE(contains(o.out,
                       "first divergence: topic /rbsim/scene, message 0, field bodies[0].mass: expected 2, "
                       "actual 2.5, difference 0.5"))
      << o;
  o = rbsim({"check", run.string(), kChainGolden.string(), "--topics", "/rbsim/body_states"});
  EXPECT_EQ(o.exit_code, 1) << o;
  EXPECT_TRUE(contains(o.out,
                       "first divergence: topic /rbsim/body_states, step 0, field bodies[0].x: expected 0.5, "
                       "actual 0.4, difference -0.1"))
      << o;
  // Table rows: topic, collapsed field path, kind, values, max |diff|, max rel, at, over tol.
  const std::regex row(R"(/rbsim/body_states +bodies\[\]\.y +float +(\d+) +(\S+) +\S+ +step \d+ +(\d+))");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(o.out, m, row)) << o;
  EXPECT_EQ(std::stoul(m[1]), 501u * 5u);  // 501 recorded steps x 5 bodies
  EXPECT_GT(std::stod(m[2]), 0.0);
  EXPECT_GT(std::stoul(m[3]), 0u);
  // With gravity changed instead, the scene description aside, the states part at step 200.
  const fs::path heavier = edited(tmp / "g", kChain, "fy=\"-1.0\"", "fy=\"-1.5\"");
  const fs::path run2 = tmp / "run2.mcap";
  record(heavier, run2, {"--record-every", kChainEvery});
  o = rbsim({"check", run2.string(), kChainGolden.string(), "--topics", "/rbsim/body_states"});
  EXPECT_EQ(o.exit_code, 1) << o;
  const std::regex first(
      R"(first divergence: topic /rbsim/body_states, step 200, field bodies\[[0-4]\]\.(x|y|theta|vx|vy|omega): expected \S+, actual \S+, difference \S+)");
  EXPECT_TRUE(std::regex_search(o.out, first)) << o;
  // Topics the change does not reach still match when they are all that is compared.
  o = rbsim({"check", run.string(), kChainGolden.string(), "--topics", "/clock"});
  EXPECT_EQ(o.exit_code, 0) << o;
}

// Copies an MCAP file leaving out one topic.
void copy_without(const fs::path& in, const fs::path& out, const std::string& topic) {
  mcap::IndexedReader reader;
  ASSERT_TRUE(reader.open(in.string()).ok());
  mcap::Writer writer;
  ASSERT_TRUE(writer.open(out.string(), recordings::writer_options(mcap::Compression::Zstd)).ok());
  for (const auto& [id, schema] : reader.schemas()) ASSERT_TRUE(writer.add_schema(schema).ok());
  for (const auto& [id, channel] : reader.channels()) {
    if (channel.topic != topic) {
      ASSERT_TRUE(writer.add_channel(channel).ok());
    }
  }
  const Status st = reader.read_messages({}, [&](const mcap::MessageEntry& e) {
    if (e.channel->topic != topic) {
      EXPECT_TRUE(writer.write_message(e.message).ok());
    }
    return true;
  });
  ASSERT_TRUE(st.ok()) << st.error().message;
  ASSERT_TRUE(writer.close().ok());
}

TEST(Check, TopicInOnlyOneFileAndTopicSelection) {
  TempDir tmp;
  const fs::path partial = tmp / "partial.mcap";
  copy_without(kChainGolden, partial, "/rbsim/springs");
  Outcome o = rbsim({"check", partial.string(), kChainGolden.string()});
  EXPECT_EQ(o.exit_code, 1) << o;
  EXPECT_TRUE(
      contains(o.out, "first divergence: topic /rbsim/springs: topic only in the golden (501 messages)"))
      << o;
  o = rbsim({"check", kChainGolden.string(), partial.string()});
  EXPECT_EQ(o.exit_code, 1) << o;
  EXPECT_TRUE(contains(o.out, "topic /rbsim/springs: topic only in the run")) << o;
  o = rbsim({"check", partial.string(), kChainGolden.string(), "--exclude-topics", "/rbsim/springs"});
  EXPECT_EQ(o.exit_code, 0) << o;
  o = rbsim(
      {"check", partial.string(), kChainGolden.string(), "--topics", "/rbsim/body_states,/rbsim/energy"});
  EXPECT_EQ(o.exit_code, 0) << o;
  EXPECT_TRUE(contains(o.out, "2 topics")) << o;
  o = rbsim({"check", partial.string(), kChainGolden.string(), "--topics", "/rbsim/nope"});
  EXPECT_EQ(o.exit_code, 2) << o;
  EXPECT_TRUE(contains(o.err, "unknown topic \"/rbsim/nope\" (topics: ")) << o;
  // Topics by their trailing names too, as rbsim record and rbsim log cat take them.
  o = rbsim({"check", partial.string(), kChainGolden.string(), "--topics", "body_states,rbsim/energy,clock"});
  EXPECT_EQ(o.exit_code, 0) << o;
  EXPECT_TRUE(contains(o.out, "3 topics")) << o;
  o = rbsim({"check", partial.string(), kChainGolden.string(), "--exclude-topics", "springs"});
  EXPECT_EQ(o.exit_code, 0) << o;
  o = rbsim({"check", partial.string(), kChainGolden.string(), "--topics", "states"});  // not a whole name
  EXPECT_EQ(o.exit_code, 2) << o;
}

// Two recordings of the cantilever for 2000 steps whose first vertex mass differs by `dm`.
struct Pair {
  TempDir tmp;
  fs::path base, other;
  explicit Pair(const std::string& mass) {
    const std::vector<std::string> opts{"--steps", "2000", "--record-every", "20"};
    base = tmp / "base.mcap";
    other = tmp / "other.mcap";
    record(kCantilever, base, opts);
    fs::create_directories(tmp / "edited");
    const fs::path scene = edited(tmp / "edited", kCantilever, "<rigidbodyvertex x=\"0\" y=\"0\" m=\"1\"/>",
                                  "<rigidbodyvertex x=\"0\" y=\"0\" m=\"" + mass + "\"/>");
    record(scene, other, opts);
  }
};

TEST(Check, TolerancesAcceptSmallDifferencesAndRejectLargeOnes) {
  const Pair tiny("1.000000001"), large("1.01");
  // Exact by default.
  Outcome o = rbsim({"check", tiny.other.string(), tiny.base.string()});
  EXPECT_EQ(o.exit_code, 1) << o;
  // An absolute tolerance covering the tiny change, not the large one.
  o = rbsim({"check", tiny.other.string(), tiny.base.string(), "--atol", "1e-5"});
  EXPECT_EQ(o.exit_code, 0) << o;
  EXPECT_TRUE(contains(o.out, ": MATCH")) << o;
  o = rbsim({"check", large.other.string(), large.base.string(), "--atol", "1e-5"});
  EXPECT_EQ(o.exit_code, 1) << o;
  EXPECT_TRUE(contains(o.out, "first divergence: topic /rbsim/scene, message 0, field bodies[0].mass")) << o;
  // Tighter than the tiny change: rejected, and the table still reports every maximum.
  o = rbsim({"check", tiny.other.string(), tiny.base.string(), "--atol", "1e-13"});
  EXPECT_EQ(o.exit_code, 1) << o;
  // A relative tolerance: the scene description's mass and inertia differ by 2.5e-10 relative.
  o = rbsim({"check", tiny.other.string(), tiny.base.string(), "--topics", "/rbsim/scene", "--rtol", "1e-9"});
  EXPECT_EQ(o.exit_code, 0) << o;
  o = rbsim(
      {"check", tiny.other.string(), tiny.base.string(), "--topics", "/rbsim/scene", "--rtol", "1e-11"});
  EXPECT_EQ(o.exit_code, 1) << o;
  o = rbsim(
      {"check", large.other.string(), large.base.string(), "--topics", "/rbsim/scene", "--rtol", "1e-9"});
  EXPECT_EQ(o.exit_code, 1) << o;
}

TEST(Check, MissingAndExtraMessages) {
  TempDir tmp;
  const fs::path shorter = tmp / "shorter.mcap";
  record(kChain, shorter, {"--steps", "99800", "--record-every", kChainEvery});
  Outcome o = rbsim({"check", shorter.string(), kChainGolden.string()});
  EXPECT_EQ(o.exit_code, 1) << o;
  EXPECT_TRUE(contains(o.out,
                       "first divergence: topic /rbsim/body_states, step 100000: message missing from the "
                       "run: run lacks steps 100000 (1 message: the run ends at step 99800)"))
      << o;
  EXPECT_TRUE(contains(o.out,
                       "steps in one file only: /rbsim/energy: run lacks steps 100000 (1 message: the run "
                       "ends at step 99800)"))
      << o;
  o = rbsim({"check", kChainGolden.string(), shorter.string()});
  EXPECT_EQ(o.exit_code, 1) << o;
  EXPECT_TRUE(
      contains(o.out,
               "first divergence: topic /rbsim/body_states, step 100000: extra message in the run: run "
               "has extra steps 100000 (1 message: the run goes on past the golden's last step 99800)"))
      << o;
}

// Copies an MCAP file leaving out the first `n` messages of every topic but the scene description
// (a recorder that joined late: the latched scene still reaches it).
void copy_joined_late(const fs::path& in, const fs::path& out, std::size_t n) {
  mcap::IndexedReader reader;
  ASSERT_TRUE(reader.open(in.string()).ok());
  mcap::Writer writer;
  ASSERT_TRUE(writer.open(out.string(), recordings::writer_options(mcap::Compression::Zstd)).ok());
  for (const auto& [id, schema] : reader.schemas()) ASSERT_TRUE(writer.add_schema(schema).ok());
  for (const auto& [id, channel] : reader.channels()) ASSERT_TRUE(writer.add_channel(channel).ok());
  std::map<std::string, std::size_t> seen;
  const Status st = reader.read_messages({}, [&](const mcap::MessageEntry& e) {
    // The latched topics reach a late joiner too.
    if (e.channel->topic == "/rbsim/scene" || e.channel->topic == "/rbsim/markers" ||
        seen[e.channel->topic]++ >= n) {
      EXPECT_TRUE(writer.write_message(e.message).ok());
    }
    return true;
  });
  ASSERT_TRUE(st.ok()) << st.error().message;
  ASSERT_TRUE(writer.close().ok());
}

// A recording that joined late pairs up by simulated step: the leading steps are reported missing
// per topic (not the first message's stamp as a field divergence).
TEST(Check, LateJoiningRecordingReportsTheMissingLeadingSteps) {
  TempDir tmp;
  const fs::path late = tmp / "late.mcap";
  copy_joined_late(kChainGolden, late, 100);  // steps 0, 200, ..., 19800 left out
  Outcome o = rbsim({"check", late.string(), kChainGolden.string()});
  EXPECT_EQ(o.exit_code, 1) << o;
  EXPECT_FALSE(contains(o.out, "stamp")) << o;
  EXPECT_TRUE(std::regex_search(
      o.out, std::regex(R"(first divergence: topic /\S+, step 0: message missing from the run: run lacks )"
                        R"(steps 0, 200, \.\.\., 19800 \(100 messages: recorder joined late\?\))")))
      << o;
  for (const char* topic :
       {"/rbsim/body_states", "/rbsim/spring_states", "/rbsim/energy", "/tf", "/rbsim/springs"}) {
    EXPECT_TRUE(
        contains(o.out, std::string("steps in one file only: ") + topic +
                            ": run lacks steps 0, 200, ..., 19800 (100 messages: recorder joined late?)"))
        << topic << "\n"
        << o;
  }
  EXPECT_TRUE(contains(o.out, "fields identical")) << o;  // the 401 steps both have match
  // The other way round: the run has steps before the golden's first.
  o = rbsim({"check", kChainGolden.string(), late.string()});
  EXPECT_EQ(o.exit_code, 1) << o;
  EXPECT_FALSE(contains(o.out, "stamp")) << o;
  EXPECT_TRUE(
      contains(o.out,
               "steps in one file only: /rbsim/body_states: run has extra steps 0, 200, ..., 19800 (100 "
               "messages: the run starts before the golden's first step 20000)"))
      << o;
  // The library reports the same per topic, and pairs the 401 common steps.
  Result<check::CheckReport> r = check::check_logs(late.string(), kChainGolden.string());
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_FALSE(r->passed());
  ASSERT_TRUE(r->first);
  EXPECT_TRUE(r->first->has_step);
  EXPECT_EQ(r->first->step, 0u);
  EXPECT_GE(r->step_problems.size(), 5u);
  EXPECT_EQ(r->diverging_values, 0u);
  for (const check::FieldStats& f : r->fields) {
    if (f.topic == "/rbsim/body_states" && f.field == "bodies[].x") {
      EXPECT_EQ(f.values, 401u * 5u);
      EXPECT_EQ(f.over, 0u);
    }
  }
}

// Another --record-every pairs the steps both recorded and names the stride as the cause.
TEST(Check, AnotherRecordEveryNamesTheStride) {
  TempDir tmp;
  const fs::path run = tmp / "every100.mcap";
  record(kChain, run, {"--record-every", "100"});
  Outcome o = rbsim({"check", run.string(), kChainGolden.string()});
  EXPECT_EQ(o.exit_code, 1) << o;
  EXPECT_FALSE(contains(o.out, "stamp")) << o;
  EXPECT_TRUE(
      contains(o.out,
               "steps in one file only: /rbsim/body_states: run has extra steps 100, 300, ..., 99900 (500 "
               "messages: golden recorded every 200th step, run every 100th (--record-every))"))
      << o;
  EXPECT_TRUE(std::regex_search(
      o.out,
      std::regex(R"(first divergence: topic /\S+, step 100: extra message in the run: run has extra )"
                 R"(steps 100, 300, \.\.\., 99900 \(500 messages: golden recorded every 200th step, run )"
                 R"(every 100th \(--record-every\)\))")))
      << o;
  o = rbsim({"check", kChainGolden.string(), run.string()});
  EXPECT_EQ(o.exit_code, 1) << o;
  EXPECT_TRUE(
      contains(o.out,
               "steps in one file only: /rbsim/body_states: run lacks steps 100, 300, ..., 99900 (500 "
               "messages: golden recorded every 100th step, run every 200th (--record-every))"))
      << o;
  // The 501 steps both recorded are identical.
  Result<check::CheckReport> r = check::check_logs(run.string(), kChainGolden.string());
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_EQ(r->diverging_values, 0u);
  EXPECT_EQ(r->diverging_messages, 500u * r->step_problems.size());
}

// The scene's file name (and its description) is metadata: reported apart, not a divergence
// unless --strict-metadata.
TEST(Check, SceneFileNameIsMetadataNotADivergence) {
  TempDir tmp;
  const fs::path scene = tmp / "mychain.xml";
  fs::copy_file(kChain, scene);
  const fs::path run = tmp / "run.mcap";
  record(scene, run, {"--record-every", kChainEvery});
  Outcome o = rbsim({"check", run.string(), kChainGolden.string()});
  EXPECT_EQ(o.exit_code, 0) << o;
  EXPECT_TRUE(contains(o.out, ": MATCH")) << o;
  EXPECT_FALSE(contains(o.out, "first divergence")) << o;
  EXPECT_TRUE(contains(o.out, "metadata differs")) << o;
  EXPECT_TRUE(contains(o.out, "  /rbsim/scene, field name: expected \"chain\", actual \"mychain\"")) << o;
  EXPECT_TRUE(std::regex_search(o.out, std::regex(R"(all \d+ fields identical)")))
      << o;  // no row for the name
  EXPECT_FALSE(std::regex_search(o.out, std::regex(R"(/rbsim/scene +name +string)"))) << o;
  Result<check::CheckReport> r = check::check_logs(run.string(), kChainGolden.string());
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_TRUE(r->passed());
  ASSERT_EQ(r->metadata.size(), 1u);
  EXPECT_EQ(r->metadata[0].where, "/rbsim/scene, field name");
  // --strict-metadata makes it a divergence.
  o = rbsim({"check", run.string(), kChainGolden.string(), "--strict-metadata"});
  EXPECT_EQ(o.exit_code, 1) << o;
  EXPECT_TRUE(
      contains(o.out,
               "first divergence: topic /rbsim/scene, message 0, field name: expected \"chain\", actual "
               "\"mychain\", difference differs"))
      << o;
  // A physics difference in the scene description still fails without it.
  fs::create_directories(tmp / "h");
  const fs::path heavier = edited(tmp / "h", scene, "<rigidbodyvertex x=\"0\" y=\"0\" m=\"1\"/>",
                                  "<rigidbodyvertex x=\"0\" y=\"0\" m=\"1.5\"/>");
  const fs::path run2 = tmp / "run2.mcap";
  record(heavier, run2, {"--record-every", kChainEvery});
  o = rbsim({"check", run2.string(), kChainGolden.string(), "--topics", "/rbsim/scene"});
  EXPECT_EQ(o.exit_code, 1) << o;
  EXPECT_TRUE(contains(o.out, "first divergence: topic /rbsim/scene, message 0, field bodies[0].mass")) << o;
  EXPECT_TRUE(contains(o.out, "field name: expected \"chain\", actual \"mychain\"")) << o;
}

TEST(Check, BadInputIsAnErrorWithExitStatus2) {
  TempDir tmp;
  const std::string golden = read_text(kChainGolden);
  std::map<std::string, fs::path> bad;
  bad["empty"] = tmp / "empty.mcap";
  write_text(bad["empty"], "");
  bad["not MCAP"] = tmp / "text.mcap";
  write_text(bad["not MCAP"], "<scene>this is not an MCAP file</scene>\n");
  bad["truncated"] = tmp / "truncated.mcap";
  write_text(bad["truncated"], golden.substr(0, golden.size() / 2));
  bad["flipped byte"] = tmp / "flipped.mcap";
  std::string flipped = golden;
  flipped[flipped.size() / 3] = static_cast<char>(flipped[flipped.size() / 3] ^ 0x5a);
  write_text(bad["flipped byte"], flipped);
  bad["missing"] = tmp / "missing.mcap";
  bad["directory"] = tmp / "dir.mcap";
  fs::create_directories(bad["directory"]);
  for (const auto& [what, path] : bad) {
    for (bool as_run : {true, false}) {
      const Outcome o = as_run ? rbsim({"check", path.string(), kChainGolden.string()})
                               : rbsim({"check", kChainGolden.string(), path.string()});
      SCOPED_TRACE(what + (as_run ? " run" : " golden"));
      EXPECT_EQ(o.exit_code, 2) << o;
      EXPECT_EQ(o.signal, 0) << o;
      EXPECT_FALSE(o.timed_out) << o;
      EXPECT_EQ(
          o.err.rfind(
              "rbsim check: error: " + std::string(as_run ? "run" : "golden") + " log " + path.string(), 0),
          0u)
          << o;
    }
  }
  EXPECT_TRUE(
      contains(rbsim({"check", bad["not MCAP"].string(), kChainGolden.string()}).err, "not an MCAP file"));
  EXPECT_TRUE(contains(rbsim({"check", bad["truncated"].string(), kChainGolden.string()}).err, "truncated"));
  EXPECT_TRUE(
      contains(rbsim({"check", bad["flipped byte"].string(), kChainGolden.string()}).err, "corrupted"));
  // Usage errors are errors too.
  EXPECT_EQ(rbsim({"check", kChainGolden.string()}).exit_code, 2);
  EXPECT_EQ(rbsim({"check", kChainGolden.string(), kChainGolden.string(), "--atol", "-1"}).exit_code, 2);
}

// Prefixes and single flipped bytes of a small recording are reported as errors (never a match,
// a divergence, a crash or a hang): every byte of the header and of the file's last 640 bytes
// (summary, summary offsets, footer, magic), every 13th byte elsewhere.
TEST(CheckLibrary, TruncatedAndFlippedBytesAreErrors) {
  TempDir tmp;
  const fs::path base = tmp / "base.mcap";
  record(kChain, base, {"--steps", "2"});
  const std::string bytes = read_text(base);
  ASSERT_GT(bytes.size(), 2000u);
  const fs::path bad = tmp / "bad.mcap";
  std::size_t n = 0;
  auto expect_error = [&](const std::string& what) {
    ++n;
    Result<check::CheckReport> r = check::check_logs(base.string(), bad.string());
    EXPECT_FALSE(r.ok()) << what << ": "
                         << (r ? (r->passed() ? "match" : "divergence " + r->first->line()) : "");
  };
  auto sampled = [&](std::size_t i) { return i < 64 || i + 640 >= bytes.size() || i % 13 == 0; };
  for (std::size_t len = 0; len < bytes.size(); ++len) {
    if (!sampled(len)) continue;
    write_text(bad, bytes.substr(0, len));
    expect_error("prefix of " + std::to_string(len) + " bytes");
  }
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    if (!sampled(i)) continue;
    std::string flipped = bytes;
    flipped[i] = static_cast<char>(flipped[i] ^ (1 << (i % 8)));
    write_text(bad, flipped);
    expect_error("bit " + std::to_string(i % 8) + " of byte " + std::to_string(i) + " flipped");
  }
  EXPECT_GT(n, 2500u);
}

// Any valid MCAP file matches itself and every other layout of the same messages (chunked or not,
// with or without indexes, summaries and repeated records): the official conformance inputs.
TEST(CheckLibrary, ConformanceFilesMatchTheirOtherLayouts) {
  const fs::path dir = kSource / "test" / "data" / "mcap-conformance";
  std::size_t files = 0;
  for (const auto& group : fs::directory_iterator(dir)) {
    if (!group.is_directory()) continue;
    std::vector<fs::path> layouts;
    for (const auto& f : fs::directory_iterator(group.path())) {
      if (f.path().extension() == ".mcap") layouts.push_back(f.path());
    }
    std::sort(layouts.begin(), layouts.end());
    for (const fs::path& f : layouts) {
      ++files;
      for (const fs::path& golden : {f, layouts.front()}) {
        Result<check::CheckReport> r = check::check_logs(f.string(), golden.string());
        ASSERT_TRUE(r) << f << " vs " << golden << ": " << r.error().message;
        EXPECT_TRUE(r->passed()) << f << " vs " << golden << ": " << r->first->line();
      }
    }
  }
  EXPECT_GT(files, 400u);
}

// The per-field maxima agree with an independent decode of both files (msgs::MessageDecoder and
// path(), nothing of the checker's own walking).
std::map<std::string, std::pair<double, std::uint64_t>> independent_max(const fs::path& run,
                                                                        const fs::path& golden) {
  auto read = [](const fs::path& path) {
    std::map<std::string, std::vector<mcap::Bytes>> messages;
    std::map<std::string, std::pair<std::string, std::string>> schemas;
    mcap::IndexedReader reader;
    EXPECT_TRUE(reader.open(path.string()).ok());
    const Status st = reader.read_messages({}, [&](const mcap::MessageEntry& e) {
      messages[e.channel->topic].push_back(e.message.data);
      schemas[e.channel->topic] = {e.schema->name, text_of(e.schema->data)};
      return true;
    });
    EXPECT_TRUE(st.ok()) << st.error().message;
    return std::pair{messages, schemas};
  };
  const auto [run_msgs, schemas] = read(run);
  const auto golden_msgs = read(golden).first;
  std::map<std::string, std::pair<double, std::uint64_t>> out;  // "topic field" -> (max |diff|, values)
  const std::regex index(R"(\[\d+\])");
  for (const auto& [topic, msgs] : golden_msgs) {
    auto decoder = msgs::MessageDecoder::create(schemas.at(topic).first, schemas.at(topic).second);
    EXPECT_TRUE(decoder.ok());
    for (std::size_t m = 0; m < msgs.size(); ++m) {
      std::vector<msgs::Scalar> a, b;
      EXPECT_TRUE(decoder->decode(run_msgs.at(topic)[m], a).ok());
      EXPECT_TRUE(decoder->decode(msgs[m], b).ok());
      EXPECT_EQ(a.size(), b.size());
      for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i) {
        if (b[i].kind != msgs::Scalar::Kind::Float) continue;
        const std::string field = std::regex_replace(decoder->path(msgs[m], i), index, "[]");
        auto& [max, values] = out[topic + " " + field];
        max = std::max(max, std::fabs(a[i].f - b[i].f));
        ++values;
      }
    }
  }
  return out;
}

TEST(CheckLibrary, FieldMaximaMatchAnIndependentDecode) {
  const Pair tiny("1.000000001");
  Result<check::CheckReport> r = check::check_logs(tiny.other.string(), tiny.base.string());
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_FALSE(r->passed());
  const auto expected = independent_max(tiny.other, tiny.base);
  std::size_t checked = 0, nonzero = 0;
  for (const check::FieldStats& f : r->fields) {
    if (f.kind != "float") continue;
    const auto it = expected.find(f.topic + " " + f.field);
    ASSERT_NE(it, expected.end()) << f.topic << " " << f.field;
    EXPECT_EQ(f.max_abs, it->second.first) << f.topic << " " << f.field;
    EXPECT_EQ(f.values, it->second.second) << f.topic << " " << f.field;
    ++checked;
    if (f.max_abs > 0) ++nonzero;
  }
  EXPECT_EQ(checked, expected.size());
  EXPECT_GT(nonzero, 20u);  // body states, spring states, energies, poses and markers all differ
}

// ---------------------------------------------------------------------------------------------
// Verification

// A recording of `scene` (an edited copy of the chain) at the chain golden's stride, in `tmp`.
fs::path record_chain_variant(const TempDir& tmp, const fs::path& scene) {
  const fs::path log_path = tmp / "chain.mcap";
  record(scene, log_path, {"--record-every", kChainEvery});
  return log_path;
}

// `log_path` verified as a golden of `scene`, with the FOSSSim reference output at hand.
Result<check::GoldenVerification> verify(const fs::path& scene, const fs::path& log_path) {
  check::GoldenVerifyOptions options;
  options.fosssim_dir = kFosssim.string();
  return check::verify_golden(scene.string(), log_path.string(), options);
}

TEST(Verify, WrongPhysicsFailsVerification) {
  // A recording made with 5% more gravity, verified as a golden of the real scene: the scene
  // description, the recorded energies and energy conservation all give it away.
  TempDir tmp;
  const fs::path scene = edited(tmp.path(), kChain, "fy=\"-1.0\"", "fy=\"-1.05\"");
  const fs::path log_path = record_chain_variant(tmp, scene);
  Result<check::GoldenVerification> v = verify(kChain, log_path);
  ASSERT_TRUE(v) << v.error().message;
  EXPECT_FALSE(v->passed) << to_string(v.value());
  auto line = [&](const std::string& prefix) {
    for (const std::string& l : v->lines) {
      if (l.rfind(prefix, 0) == 0) return true;
    }
    return false;
  };
  EXPECT_TRUE(line("FAIL scene description")) << to_string(v.value());
  EXPECT_TRUE(line("FAIL energy terms")) << to_string(v.value());
  EXPECT_TRUE(line("FAIL energy conservation")) << to_string(v.value());
  EXPECT_GT(v->energy_error, 10 * v->energy_bound);
  // The same recording is a fine golden of the scene it was made from.
  v = verify(scene, log_path);
  ASSERT_TRUE(v) << v.error().message;
  EXPECT_TRUE(v->passed) << to_string(v.value());
  EXPECT_LT(v->energy_error, v->energy_bound);
}

TEST(Verify, WrongWindFailsTheIndependentIntegration) {
  // A FOSSSim wind scene recorded with the wind 10% stronger, verified as a golden of the real
  // scene: wind has no potential, so only the re-integration can tell (and it does).
  TempDir tmp;
  const fs::path original = kFosssim / "scenes" / "windtests" / "test00sym.xml";
  const std::string text = read_text(original);
  const std::size_t at = text.find("beta=\"");
  ASSERT_NE(at, std::string::npos);
  const std::size_t end = text.find('"', at + 6);
  const double beta = std::stod(text.substr(at + 6, end - at - 6));
  std::ostringstream stronger;
  stronger.precision(17);
  stronger << "beta=\"" << beta * 1.1;
  const fs::path scene = edited(tmp.path(), original, text.substr(at, end - at), stronger.str());
  const fs::path log_path = tmp / "windy.mcap";
  record(scene, log_path, {"--record-every", "10"});
  Result<check::GoldenVerification> v = check::verify_golden(original.string(), log_path.string());
  ASSERT_TRUE(v) << v.error().message;
  EXPECT_FALSE(v->passed) << to_string(v.value());
  EXPECT_TRUE(contains(to_string(v.value()), "PASS energy terms")) << to_string(v.value());
  EXPECT_TRUE(contains(to_string(v.value()), "FAIL independent integration")) << to_string(v.value());
  v = check::verify_golden(scene.string(), log_path.string());
  ASSERT_TRUE(v) << v.error().message;
  EXPECT_TRUE(v->passed) << to_string(v.value());
  EXPECT_EQ(v->rule, "independent-integration");
}

// Springs of one colour travel as the springs marker's single color (no per-vertex colours), and
// verification checks the colours against the scene file: a chain recorded with every spring red
// is no golden of the chain (default spring colour), but is one of its own scene.
TEST(Verify, OneSpringColourIsCheckedAgainstTheScene) {
  TempDir tmp;
  std::string red;
  for (int k = 0; k < 5; ++k)
    red += "  <rigidbodyspringcolor spring=\"" + std::to_string(k) + "\" r=\"1\" g=\"0\" b=\"0\"/>\n";
  const fs::path scene = edited(tmp.path(), kChain, "</scene>", red + "</scene>");
  const fs::path log_path = record_chain_variant(tmp, scene);
  Result<check::GoldenVerification> v = verify(kChain, log_path);
  ASSERT_TRUE(v) << v.error().message;
  EXPECT_FALSE(v->passed) << to_string(v.value());
  EXPECT_TRUE(contains(to_string(v.value()), "FAIL scene description")) << to_string(v.value());
  EXPECT_TRUE(contains(to_string(v.value()), "spring 0 colour r")) << to_string(v.value());
  v = verify(scene, log_path);
  ASSERT_TRUE(v) << v.error().message;
  EXPECT_TRUE(v->passed) << to_string(v.value());
  EXPECT_TRUE(contains(to_string(v.value()), "PASS springs marker")) << to_string(v.value());
}

TEST(Verify, ErrorsOnBadInput) {
  TempDir tmp;
  write_text(tmp / "empty.mcap", "");
  EXPECT_FALSE(check::verify_golden(kChain.string(), (tmp / "empty.mcap").string()).ok());
  EXPECT_FALSE(check::verify_golden((tmp / "missing.xml").string(), kChainGolden.string()).ok());
  const Outcome o = rbsim({"check", "--verify-golden", kChain.string(), (tmp / "empty.mcap").string()});
  EXPECT_EQ(o.exit_code, 2) << o;
}

// ---------------------------------------------------------------------------------------------
// scripts/golden

TEST(Script, RegeneratesAVerifiedGolden) {
  TempDir tmp;
  const Outcome o = run_process("/bin/bash", {(kSource / "scripts" / "golden").string(), kChain.string()},
                                {std::string("RBSIM=") + RBSIM_EXE, "RBSIM_GOLDEN_DIR=" + tmp.path().string(),
                                 "RBSIM_FOSSSIM_DIR=" + kFosssim.string()});
  ASSERT_EQ(o.exit_code, 0) << o;
  EXPECT_TRUE(contains(o.out, "verified (symplectic-energy, independent-integration), --record-every 200"))
      << o;
  const Outcome c = rbsim({"check", (tmp / "chain.mcap").string(), kChainGolden.string()});
  EXPECT_EQ(c.exit_code, 0) << c;
  for (const auto& entry : fs::directory_iterator(tmp.path())) {
    EXPECT_EQ(entry.path().filename(), "chain.mcap") << "left behind: " << entry.path();
  }
}

TEST(Script, RefusesAGoldenThatFailsVerification) {
  // An rbsim whose `run` simulates 5% more gravity than the scene asks for: its recording of
  // chain.xml fails verification, so scripts/golden must refuse it and keep the old golden.
  TempDir tmp;
  const fs::path wrong = edited(tmp / "wrong", kChain, "fy=\"-1.0\"", "fy=\"-1.05\"");
  const fs::path fake = tmp / "fake-rbsim";
  write_text(fake, "#!/bin/bash\nif [ \"$1\" = run ]; then shift 2; exec '" + std::string(RBSIM_EXE) +
                       "' run '" + wrong.string() + "' \"$@\"; fi\nexec '" + std::string(RBSIM_EXE) +
                       "' \"$@\"\n");
  fs::permissions(fake, fs::perms::owner_all);
  fs::create_directories(tmp / "out");
  const fs::path old_golden = tmp / "out" / "chain.mcap";
  write_text(old_golden, "the old golden");
  const Outcome o = run_process("/bin/bash", {(kSource / "scripts" / "golden").string(), kChain.string()},
                                {"RBSIM=" + fake.string(), "RBSIM_GOLDEN_DIR=" + (tmp / "out").string(),
                                 "RBSIM_FOSSSIM_DIR=" + kFosssim.string()});
  EXPECT_EQ(o.exit_code, 1) << o;
  EXPECT_TRUE(contains(o.err, "refused")) << o;
  EXPECT_TRUE(contains(o.err, "FAIL energy conservation")) << o;
  EXPECT_EQ(read_text(old_golden), "the old golden");
  std::size_t files = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(tmp / "out")) ++files;
  EXPECT_EQ(files, 1u);  // no temporary left behind
}

}  // namespace
