// One rule per shared decision, seen from the command line: the commands that take the same input
// decide the same about it (issue 36, point 2). Which topics a name selects and how an unknown one
// is worded (msgs::select_topics, also for an enclave's permissions); whether a path is a recording or a
// scene (recordings::path_kind); seconds to nanoseconds (rbsim::seconds_to_ns). DDS commands on rbsim's
// loopback configuration, on a domain no other test uses.
#include <gtest/gtest.h>

#include <filesystem>
#include <set>
#include <string>

#include "rbsim/subprocess.hpp"

namespace rbsim {
namespace {

namespace fs = std::filesystem;
using test::rbsim;

constexpr const char* kQuietDomain = "229";
const std::string kScene = std::string(RBSIM_TEST_DATA_DIR) + "/../../scenes/chain.xml";  // dt 1 ms
// The topics rbsim run --record writes by default, as the selector lists them (sorted).
constexpr const char* kRecorded =
    "(topics: /clock, /rbsim/body_states, /rbsim/energy, /rbsim/markers, /rbsim/scene, /rbsim/spring_states, "
    "/rbsim/springs, /tf)";

fs::path record(const test::TempDir& dir, const std::string& name) {
  const fs::path out = dir / name;
  const test::Outcome o = rbsim({"run", kScene, "-q", "--steps", "20", "--record", out.string()});
  EXPECT_EQ(o.exit_code, 0) << o;
  return out;
}

// The topics of `rbsim log cat` output lines (JSON: {"topic":"...",...}).
std::set<std::string> topics_of(const std::string& out) {
  std::set<std::string> topics;
  for (const std::string& line : test::lines_of(out)) {
    const auto at = line.find("\"topic\":\"");
    if (at == std::string::npos) continue;
    const auto begin = at + 9;
    topics.insert(line.substr(begin, line.find('"', begin) - begin));
  }
  return topics;
}

TEST(SharedRules, AnUnknownTopicIsWordedAlikeByEveryCommand) {
  test::TempDir dir;
  const std::string run = record(dir, "run.mcap").string();
  const std::string unknown = std::string("unknown topic \"/rbsim/nope\" ") + kRecorded;
  // Commands that select among a recording's topics: the same list, the same words.
  const test::Outcome cat = rbsim({"log", "cat", run, "--topics", "body_states,/rbsim/nope"});
  EXPECT_EQ(cat.exit_code, 1) << cat;
  EXPECT_NE(cat.err.find("rbsim log cat: error: " + run + ": " + unknown), std::string::npos) << cat;
  const test::Outcome filter =
      rbsim({"log", "filter", run, (dir / "f.mcap").string(), "--exclude-topics", "/rbsim/nope"});
  EXPECT_EQ(filter.exit_code, 1) << filter;
  EXPECT_NE(filter.err.find(run + ": " + unknown), std::string::npos) << filter;
  const test::Outcome check = rbsim({"check", run, run, "--topics", "/rbsim/nope"});
  EXPECT_EQ(check.exit_code, 2) << check;
  EXPECT_NE(check.err.find("rbsim check: error: " + unknown), std::string::npos) << check;
  const test::Outcome replay = rbsim({"replay", run, "--domain", kQuietDomain, "--topics", "/rbsim/nope"});
  EXPECT_EQ(replay.exit_code, 1) << replay;
  EXPECT_NE(replay.err.find(run + ": " + unknown), std::string::npos) << replay;
  // Commands that select among rbsim's own topics: the same words over their list.
  const test::Outcome live =
      rbsim({"run", kScene, "--record", (dir / "x.mcap").string(), "--topics", "nope"});
  EXPECT_EQ(live.exit_code, 2) << live;
  EXPECT_NE(live.err.find("unknown topic \"nope\" (topics: /clock, /rbsim/body_states, "), std::string::npos)
      << live;
  const test::Outcome rec =
      rbsim({"record", (dir / "y.mcap").string(), "--domain", kQuietDomain, "--topics", "nope"});
  EXPECT_EQ(rec.exit_code, 1) << rec;
  EXPECT_NE(rec.err.find("unknown topic \"nope\" (topics: /clock, /rbsim/body_states, /rbsim/commands, "),
            std::string::npos)
      << rec;
  // The enclave's permissions name topics the same way: the same words, and no keystore file
  // touched for a name that selects nothing.
  const fs::path ks = dir / "keystore";
  const test::Outcome keystore = rbsim({"security", "create-keystore", ks.string()});
  ASSERT_EQ(keystore.exit_code, 0) << keystore;
  const test::Outcome enclave =
      rbsim({"security", "create-enclave", ks.string(), "/rbsim", "--topics", "scene,nope"});
  EXPECT_EQ(enclave.exit_code, 1) << enclave;
  EXPECT_NE(enclave.err.find("unknown topic \"nope\" (topics: /clock, /rbsim/body_states, /rbsim/commands, "),
            std::string::npos)
      << enclave;
  EXPECT_FALSE(fs::exists(ks / "enclaves/rbsim")) << "an enclave was made for a bad --topics";
}

TEST(SharedRules, LogCatAndCheckSelectTheSameTopics) {
  test::TempDir dir;
  const std::string run = record(dir, "run.mcap").string();
  for (const std::string topics : {"body_states,clock", "/rbsim/body_states,/clock", "rbsim/energy", "tf"}) {
    const test::Outcome cat = rbsim({"log", "cat", run, "--topics", topics});
    ASSERT_EQ(cat.exit_code, 0) << cat;
    const std::set<std::string> chosen = topics_of(cat.out);
    ASSERT_FALSE(chosen.empty()) << topics;
    const test::Outcome check = rbsim({"check", run, run, "--topics", topics});
    ASSERT_EQ(check.exit_code, 0) << check;
    const std::string count = std::to_string(chosen.size()) + (chosen.size() == 1 ? " topic," : " topics,");
    EXPECT_NE(check.out.find(count), std::string::npos) << topics << "\n" << check;
  }
}

TEST(SharedRules, RenderPlotAndRunCommandsTellARecordingFromAScriptAlike) {
  test::TempDir dir;
  const fs::path run = record(dir, "run.mcap");
  // A recording under a name without .mcap: a recording by its magic, for plot and run --commands.
  const fs::path renamed = dir / "run.bin";
  fs::copy_file(run, renamed);
  fs::create_directory(dir / "bag");  // a directory: a bag (without its metadata.yaml here)
  for (const fs::path& input : {run, renamed, dir / "bag"}) {
    const test::Outcome plot =
        rbsim({"plot", input.string(), "--out", (dir / "p.png").string(), "--duration", "1"});
    EXPECT_EQ(plot.exit_code, 2) << input << "\n" << plot;
    EXPECT_NE(plot.err.find("--duration applies to a scene, not to a recording"), std::string::npos) << plot;
    const test::Outcome commands = rbsim({"run", kScene, "-q", "--steps", "5", "--commands", input.string()});
    EXPECT_EQ(commands.err.find("YAML"), std::string::npos) << input << "\n" << commands;  // not a script
  }
  // The recording and its renamed copy give the same run.
  const test::Outcome a = rbsim({"run", kScene, "-q", "--steps", "5", "--commands", run.string()});
  const test::Outcome b = rbsim({"run", kScene, "-q", "--steps", "5", "--commands", renamed.string()});
  EXPECT_EQ(a.exit_code, b.exit_code) << a << b;
  // A scene is no recording: plot takes --duration for it (and fails later only for want of gnuplot).
  const test::Outcome scene =
      rbsim({"plot", kScene, "--out", (dir / "s.png").string(), "--duration", "0.01"});
  EXPECT_EQ(scene.err.find("not to a recording"), std::string::npos) << scene;
}

TEST(SharedRules, SecondsBecomeTheSameNanosecondsInEveryLogTool) {
  test::TempDir dir;
  const std::string run = record(dir, "run.mcap").string();
  // Window edges on, and half a nanosecond around, the stamps of steps 3 and 7 (round to nearest).
  for (const auto& [start, end] :
       {std::pair{"0.003", "0.007"}, std::pair{"0.0030000000004", "0.0069999999996"},
        std::pair{"0.0030000000006", "0.0070000000006"}}) {
    const test::Outcome cat = rbsim({"log", "cat", run, "--start", start, "--end", end});
    ASSERT_EQ(cat.exit_code, 0) << cat;
    const fs::path out = dir / "window.mcap";
    const test::Outcome filter =
        rbsim({"log", "filter", run, out.string(), "--overwrite", "--start", start, "--end", end});
    ASSERT_EQ(filter.exit_code, 0) << filter;
    const test::Outcome filtered = rbsim({"log", "cat", out.string()});
    ASSERT_EQ(filtered.exit_code, 0) << filtered;
    // The latched topics are kept whole by a filter; compare the per-step messages.
    std::size_t in_cat = 0, in_filter = 0;
    for (const std::string& l : test::lines_of(cat.out))
      in_cat += l.find("\"/rbsim/body_states\"") != std::string::npos;
    for (const std::string& l : test::lines_of(filtered.out))
      in_filter += l.find("\"/rbsim/body_states\"") != std::string::npos;
    EXPECT_EQ(in_cat, in_filter) << start << " " << end;
    EXPECT_GT(in_cat, 0u);
  }
  // A duration that is none is refused in the one wording.
  const test::Outcome inf = rbsim({"record", (dir / "bag").string(), "--domain", kQuietDomain,
                                   "--max-file-duration", "inf", "--wall-duration", "0.2"});
  EXPECT_EQ(inf.exit_code, 2) << inf;
  EXPECT_NE(
      inf.err.find("--max-file-duration: inf s is not a duration: seconds must be finite, at least 0 and "
                   "at most 9223372036"),
      std::string::npos)
      << inf;
}

}  // namespace
}  // namespace rbsim
