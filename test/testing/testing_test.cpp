// rbsim::testing: RecordScene, CheckLogs and UpdateGoldenIfRequested as a user's test calls them.
#include "rbsim/testing.hpp"

#include <cstdlib>
#include <filesystem>
#include <regex>

#include "rbsim/subprocess.hpp"

namespace {

namespace fs = std::filesystem;
using rbsim::test::read_text;
using rbsim::test::TempDir;
using rbsim::test::write_text;
using namespace rbsim::testing;

const std::string kScenes = RBSIM_SOURCE_DIR "/scenes/";
const std::string kPendulum = RBSIM_SOURCE_DIR "/examples/golden-check/pendulum.xml";

// Sets RBSIM_UPDATE_GOLDENS for one scope.
class UpdateGoldens {
 public:
  explicit UpdateGoldens(const char* value) { ::setenv(kUpdateGoldensVariable, value, 1); }
  ~UpdateGoldens() { ::unsetenv(kUpdateGoldensVariable); }
};

std::string message(const ::testing::AssertionResult& r) {
  return r.message();
}

TEST(RecordScene, WritesWhatRbsimRunRecordWrites) {
  TempDir dir;
  const std::string api = dir.path() / "api.mcap", cli = dir.path() / "cli.mcap";
  ASSERT_TRUE(RecordScene(kScenes + "chain.xml", api, {.steps = 300, .record_every = 7}));
  const auto run = rbsim::test::rbsim(
      {"run", kScenes + "chain.xml", "--steps", "300", "--record", cli, "--record-every", "7", "--quiet"});
  ASSERT_EQ(run.exit_code, 0) << run;
  EXPECT_TRUE(read_text(api) == read_text(cli)) << "RecordScene and rbsim run --record differ";
}

// A golden with perturbations: RecordScene takes rbsim run --commands' scripts (and recordings).
TEST(RecordScene, TakesCommandsAsRbsimRunDoes) {
  TempDir dir;
  const std::string script = dir.path() / "kick.yaml";
  write_text(script,
             "- {step: 50, set: {forces.0.fy: -3.7}}\n- {t: 0.1, impulse: {body: 2, j: [0.5, 2.0]}}\n");
  const std::string api = dir.path() / "api.mcap", cli = dir.path() / "cli.mcap",
                    plain = dir.path() / "plain.mcap";
  ASSERT_TRUE(RecordScene(kScenes + "chain.xml", api, {.steps = 300, .commands = script}));
  const auto run = rbsim::test::rbsim(
      {"run", kScenes + "chain.xml", "--steps", "300", "--record", cli, "--commands", script, "--quiet"});
  ASSERT_EQ(run.exit_code, 0) << run;
  EXPECT_TRUE(read_text(api) == read_text(cli)) << "RecordScene and rbsim run --commands differ";
  ASSERT_TRUE(RecordScene(kScenes + "chain.xml", plain, {.steps = 300}));
  EXPECT_FALSE(CheckLogs(api, plain));
  // Its own recording as the commands: the same file again.
  const std::string again = dir.path() / "again.mcap";
  ASSERT_TRUE(RecordScene(kScenes + "chain.xml", again, {.steps = 300, .commands = api}));
  EXPECT_TRUE(read_text(again) == read_text(api));
  // A bad script names its line and field; nothing is written.
  write_text(script, "- {step: 50, impulse: {body: 99, j: [0, 1]}}\n");
  const std::string bad = dir.path() / "bad.mcap";
  const auto refused = RecordScene(kScenes + "chain.xml", bad, {.steps = 300, .commands = script});
  EXPECT_FALSE(refused);
  EXPECT_NE(message(refused).find("kick.yaml:1: impulse.body"), std::string::npos) << message(refused);
  EXPECT_FALSE(fs::exists(bad));
}

TEST(RecordScene, RefusesAnExistingOutputUnlessOverwrite) {
  TempDir dir;
  const std::string out = dir.path() / "run.mcap";
  write_text(out, "mine");
  const auto refused = RecordScene(kPendulum, out, {.steps = 5});
  EXPECT_FALSE(refused);
  EXPECT_NE(message(refused).find("exists (use RecordOptions::overwrite to replace it)"), std::string::npos)
      << message(refused);
  EXPECT_EQ(read_text(out), "mine");
  EXPECT_TRUE(RecordScene(kPendulum, out, {.steps = 5, .overwrite = true}));
  EXPECT_NE(read_text(out), "mine");
}

TEST(RecordScene, ReportsBadInput) {
  TempDir dir;
  const std::string out = dir.path() / "run.mcap";
  EXPECT_NE(message(RecordScene(dir.path() / "missing.xml", out)).find("missing.xml"), std::string::npos);
  EXPECT_NE(message(RecordScene(kPendulum, out, {.topics = {"nope"}})).find("unknown topic \"nope\""),
            std::string::npos);
  EXPECT_NE(message(RecordScene(kPendulum, out, {.steps = -1})).find("steps must be >= 0"),
            std::string::npos);
  EXPECT_NE(message(RecordScene(kPendulum, out, {.record_every = 0})).find("record_every"),
            std::string::npos);
  EXPECT_FALSE(fs::exists(out));
}

// A run that diverges is a failure naming the step, and writes nothing: an older file at out_mcap
// (a golden being updated with overwrite) stays as it was.
TEST(RecordScene, ADivergingRunWritesNothing) {
  TempDir dir;
  std::string text = read_text(RBSIM_SOURCE_DIR "/test/data/fosssim/scenes/springtests/test00ee.xml");
  const std::string k = "k=\"";
  for (std::size_t at = text.find(k); at != std::string::npos; at = text.find(k, at + 1))
    text.replace(at + k.size(), text.find('"', at + k.size()) - (at + k.size()), "1e9");
  const std::string stiff = dir.path() / "stiff.xml", out = dir.path() / "run.mcap";
  write_text(stiff, text);
  write_text(out, "an older golden");
  const auto r = RecordScene(stiff, out, {.overwrite = true});
  EXPECT_FALSE(r);
  EXPECT_NE(message(r).find("not finite"), std::string::npos) << message(r);
  EXPECT_EQ(read_text(out), "an older golden");
}

TEST(CheckLogs, MatchesAnIdenticalRun) {
  TempDir dir;
  const std::string a = dir.path() / "a.mcap", b = dir.path() / "b.mcap";
  ASSERT_TRUE(RecordScene(kPendulum, a, {.steps = 50}));
  ASSERT_TRUE(RecordScene(kPendulum, b, {.steps = 50}));
  const auto r = CheckLogs(a, b);
  EXPECT_TRUE(r) << message(r);
  EXPECT_NE(message(r).find("MATCH"), std::string::npos) << message(r);
}

TEST(CheckLogs, ExplainsADivergenceWithRbsimChecksReport) {
  TempDir dir;
  // The same scene with a stiffer spring: every value after step 0 moves.
  std::string text = read_text(kPendulum);
  text = std::regex_replace(text, std::regex("k=\"40.0\""), "k=\"41.0\"");
  const std::string stiffer = dir.path() / "stiffer.xml";
  write_text(stiffer, text);
  const std::string run = dir.path() / "run.mcap", golden = dir.path() / "golden.mcap";
  ASSERT_TRUE(RecordScene(stiffer, run, {.steps = 50}));
  ASSERT_TRUE(RecordScene(kPendulum, golden, {.steps = 50}));
  const auto r = CheckLogs(run, golden);
  ASSERT_FALSE(r);
  const std::string m = message(r);
  for (const char* part : {"DIVERGED", "first divergence: topic /rbsim/scene", "expected", "actual",
                           "per-field max error", "/rbsim/body_states"}) {
    EXPECT_NE(m.find(part), std::string::npos) << part << " not in\n" << m;
  }
  // The same report as the command line's (which adds its timing).
  const auto cli = rbsim::test::rbsim({"check", run, golden});
  EXPECT_EQ(cli.exit_code, 1) << cli;
  EXPECT_EQ(cli.out.substr(0, cli.out.rfind("MB of message data")),
            m.substr(0, m.rfind("MB of message data")));
  // A tolerance wide enough passes (spring stiffness is a scene value, compared like any other).
  EXPECT_TRUE(CheckLogs(run, golden, {.atol = 10.0}));
}

TEST(CheckLogs, SaysWhenTheGoldenIsOfAnotherScene) {
  TempDir dir;
  const std::string run = dir.path() / "run.mcap", golden = dir.path() / "golden.mcap";
  ASSERT_TRUE(RecordScene(kPendulum, run, {.steps = 20}));
  ASSERT_TRUE(RecordScene(kScenes + "chain.xml", golden, {.steps = 20}));
  const std::string m = message(CheckLogs(run, golden));
  EXPECT_NE(m.find("different scenes: the run and the golden record different scenes (golden 'chain', run "
                   "'pendulum'): bodies: golden 5, run 1"),
            std::string::npos)
      << m;
  EXPECT_EQ(m.find("per-field max error"), std::string::npos) << m;
}

TEST(CheckLogs, FailsCleanlyOnUnreadableInput) {
  TempDir dir;
  const std::string run = dir.path() / "run.mcap", text = dir.path() / "notes.txt";
  ASSERT_TRUE(RecordScene(kPendulum, run, {.steps = 5}));
  write_text(text, "not a recording\n");
  const std::string missing = message(CheckLogs(run, dir.path() / "missing.mcap"));
  EXPECT_NE(missing.find("missing.mcap"), std::string::npos) << missing;
  const std::string not_mcap = message(CheckLogs(text, run));
  EXPECT_NE(not_mcap.find("not an MCAP file"), std::string::npos) << not_mcap;
  EXPECT_FALSE(CheckLogs(text, run));
}

TEST(UpdateGoldenIfRequested, ChecksWithoutTheVariable) {
  TempDir dir;
  const std::string run = dir.path() / "run.mcap", golden = dir.path() / "golden.mcap";
  ASSERT_TRUE(RecordScene(kPendulum, run, {.steps = 30}));
  const std::string m = message(UpdateGoldenIfRequested(kPendulum, run, golden));
  EXPECT_NE(m.find("RBSIM_UPDATE_GOLDENS=1"), std::string::npos) << m;
  EXPECT_FALSE(fs::exists(golden));
  fs::copy_file(run, golden);
  EXPECT_TRUE(UpdateGoldenIfRequested(kPendulum, run, golden));
  UpdateGoldens zero("0");
  EXPECT_FALSE(GoldenUpdateRequested());
}

TEST(UpdateGoldenIfRequested, WritesAVerifiedGolden) {
  TempDir dir;
  const std::string run = dir.path() / "run.mcap", golden = dir.path() / "golden.mcap";
  ASSERT_TRUE(RecordScene(kPendulum, run, {.steps = 30}));
  write_text(golden, "stale");
  UpdateGoldens on("1");
  const auto r = UpdateGoldenIfRequested(kPendulum, run, golden);
  EXPECT_TRUE(r) << message(r);
  EXPECT_NE(message(r).find("verified"), std::string::npos) << message(r);
  EXPECT_TRUE(read_text(golden) == read_text(run));
}

TEST(UpdateGoldenIfRequested, RefusesARecordingTheVerifierRejects) {
  TempDir dir;
  const std::string run = dir.path() / "run.mcap", golden = dir.path() / "golden.mcap";
  // A recording of another scene is no golden of the pendulum.
  ASSERT_TRUE(RecordScene(kScenes + "chain.xml", run, {.steps = 30}));
  UpdateGoldens on("1");
  const std::string m = message(UpdateGoldenIfRequested(kPendulum, run, golden));
  EXPECT_NE(m.find("refusing to write golden"), std::string::npos) << m;
  EXPECT_NE(m.find("FAIL"), std::string::npos) << m;
  EXPECT_FALSE(fs::exists(golden));
}

}  // namespace
