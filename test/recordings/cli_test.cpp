// rbsim log through the real binary (subprocess, time-bounded): export against rbsim run's own
// CSV files byte for byte, info/doctor/recover on good files, and every tool on bad inputs.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <array>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <utility>

#include "rbsim/subprocess.hpp"
#include "recordings_test_util.hpp"

namespace rbsim::test {
namespace {

namespace fs = std::filesystem;
using std::chrono::seconds;

std::string describe(const Outcome& o) {
  return "exit " + std::to_string(o.exit_code) + (o.timed_out ? " (timed out)" : "") +
         (o.signal ? " (signal " + std::to_string(o.signal) + ")" : "") + "\nstdout:\n" +
         o.out.substr(0, 2000) + "\nstderr:\n" + o.err.substr(0, 2000);
}

// The per-step lines of `csv` (after its header) whose step is a multiple of k.
std::string every_kth_step(const std::string& csv, std::int64_t k) {
  std::string out;
  bool header = true;
  for (const std::string& line : lines_of(csv)) {
    if (header || std::stoll(line.substr(0, line.find(','))) % k == 0) out += line + "\n";
    header = false;
  }
  return out;
}

// A scene with several bodies and three gravity fields: World::energy() sums every body of every
// field into one running total, which adding the per-field EnergyTerms entries does not
// reproduce, so export recomputes U_gravity.
std::string three_gravity_scene(const TempDir& dir) {
  std::string xml = read_text(source_path("scenes/cantilever.xml"));  // five bodies, springs
  const std::string g = "<rigidbodygravityforce fx=\"0.0\" fy=\"-1.0\"/>";
  const auto at = xml.find(g);
  EXPECT_NE(at, std::string::npos);
  xml.insert(at + g.size(),
             "\n  <rigidbodygravityforce fx=\"0.37\" fy=\"-1.3\"/>\n  <rigidbodygravityforce fx=\"-0.1\" "
             "fy=\"0.77\"/>");
  const fs::path path = dir / "three_gravity.xml";
  write_text(path, xml);
  return path.string();
}

struct ExportCase {
  std::string name, scene;  // scene relative to the repository ("@3g": generated)
  std::vector<std::string> run_args;
};

void PrintTo(const ExportCase& c, std::ostream* os) {
  *os << c.name;
}

class ExportMatchesRun : public ::testing::TestWithParam<ExportCase> {};

TEST_P(ExportMatchesRun, ByteForByte) {
  TempDir dir;
  const ExportCase& c = GetParam();
  const std::string scene = c.scene == "@3g" ? three_gravity_scene(dir) : source_path(c.scene);
  std::vector<std::string> args = {"run",
                                   scene,
                                   "-q",
                                   "--csv",
                                   (dir / "run.csv").string(),
                                   "--energy-csv",
                                   (dir / "run_energy.csv").string(),
                                   "--record",
                                   (dir / "r.mcap").string()};
  args.insert(args.end(), c.run_args.begin(), c.run_args.end());
  Outcome run = rbsim(args, seconds(120));
  ASSERT_EQ(run.exit_code, 0) << describe(run);
  Outcome exp = rbsim({"log", "export", (dir / "r.mcap").string(), "--csv", (dir / "x.csv").string(),
                       "--energy-csv", (dir / "x_energy.csv").string()},
                      seconds(120));
  ASSERT_EQ(exp.exit_code, 0) << describe(exp);
  const std::string run_csv = read_text(dir / "run.csv"), run_energy = read_text(dir / "run_energy.csv");
  ASSERT_GT(lines_of(run_energy).size(), 100u);
  // Compared as whole files (EXPECT_EQ on megabytes would print them all on failure).
  EXPECT_TRUE(read_text(dir / "x.csv") == run_csv) << "per-body CSV differs";
  EXPECT_TRUE(read_text(dir / "x_energy.csv") == run_energy) << "energy CSV differs";
  const auto a = lines_of(read_text(dir / "x_energy.csv")), b = lines_of(run_energy);
  for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i) {
    if (a[i] != b[i]) {
      ADD_FAILURE() << "first energy difference at line " << i << ":\n  export: " << a[i]
                    << "\n  run:    " << b[i];
      break;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(
    Scenes, ExportMatchesRun,
    ::testing::Values(ExportCase{"cantilever_springs_gravity", "scenes/cantilever.xml", {"--steps", "300"}},
                      ExportCase{
                          "fosssim_wind_gravity", "test/data/fosssim/scenes/windtests/test06ee.xml", {}},
                      ExportCase{"airplane_spring_gravity_wind", "scenes/airplane.xml", {"--steps", "3000"}},
                      ExportCase{"three_gravity_fields", "@3g", {"--steps", "2000"}},
                      ExportCase{"lz4_custom_namespace",
                                 "scenes/chain.xml",
                                 {"--steps", "500", "--compression", "lz4", "--namespace", "sim"}}),
    [](const auto& param_info) { return param_info.param.name; });

TEST(ExportCli, RecordEveryThreeExportsExactlyTheRecordedSteps) {
  TempDir dir;
  const std::string scene = source_path("scenes/cantilever.xml");
  Outcome run = rbsim({"run", scene, "-q", "--steps", "301", "--csv", (dir / "run.csv").string(),
                       "--energy-csv", (dir / "run_energy.csv").string(), "--record",
                       (dir / "r.mcap").string(), "--record-every", "3"});
  ASSERT_EQ(run.exit_code, 0) << describe(run);
  Outcome exp = rbsim({"log", "export", (dir / "r.mcap").string(), "--csv", (dir / "x.csv").string(),
                       "--energy-csv", (dir / "x_energy.csv").string()});
  ASSERT_EQ(exp.exit_code, 0) << describe(exp);
  EXPECT_NE(exp.err.find("101 steps (0..300)"), std::string::npos) << exp.err;
  EXPECT_TRUE(read_text(dir / "x.csv") == every_kth_step(read_text(dir / "run.csv"), 3));
  const std::string energy = read_text(dir / "x_energy.csv");
  EXPECT_TRUE(energy == every_kth_step(read_text(dir / "run_energy.csv"), 3));
  EXPECT_EQ(lines_of(energy).size(), 1u + 101u);
}

// --compression-level changes the chunk bytes, never the messages; a level the codec has no use
// for is a one-line error before anything is written.
TEST(RecordCli, CompressionLevelChangesBytesNotMessages) {
  TempDir dir;
  const std::string scene = source_path("scenes/cantilever.xml");
  const auto record = [&](const std::string& name, std::vector<std::string> extra) {
    std::vector<std::string> args = {"run", scene, "-q", "--steps", "400", "--record", (dir / name).string()};
    args.insert(args.end(), extra.begin(), extra.end());
    return rbsim(args);
  };
  ASSERT_EQ(record("default.mcap", {}).exit_code, 0);
  for (const std::vector<std::string>& extra :
       std::vector<std::vector<std::string>>{{"--compression-level", "19"},
                                             {"--compression-level", "-5"},
                                             {"--compression", "lz4", "--compression-level", "9"}}) {
    const std::string name = "level" + extra.back() + ".mcap";
    Outcome o = record(name, extra);
    ASSERT_EQ(o.exit_code, 0) << describe(o);
    EXPECT_NE(read_text(dir / name), read_text(dir / "default.mcap")) << extra.back();
    Outcome check = rbsim({"check", (dir / name).string(), (dir / "default.mcap").string()});
    EXPECT_EQ(check.exit_code, 0) << describe(check);
  }
  for (const std::vector<std::string>& bad :
       std::vector<std::vector<std::string>>{{"--compression-level", "23"},
                                             {"--compression", "lz4", "--compression-level", "13"},
                                             {"--compression", "none", "--compression-level", "1"}}) {
    Outcome o = record("bad.mcap", bad);
    EXPECT_EQ(o.exit_code, 1) << describe(o);
    EXPECT_NE(o.err.find("rbsim run: error: --compression-level: "), std::string::npos) << o.err;
    EXPECT_EQ(lines_of(o.err).size(), 1u) << o.err;
    EXPECT_FALSE(fs::exists(dir / "bad.mcap"));
  }
}

TEST(ExportCli, ErrorsAreOneLine) {
  TempDir dir;
  Outcome run = rbsim({"run", source_path("scenes/chain.xml"), "-q", "--steps", "20", "--record",
                       (dir / "r.mcap").string(), "--namespace", "a"});
  ASSERT_EQ(run.exit_code, 0) << describe(run);
  const std::string file = (dir / "r.mcap").string();
  struct Case {
    std::vector<std::string> args;
    std::string needle;
  };
  const std::vector<Case> cases = {
      {{"log", "export", file}, "nothing to export"},
      {{"log", "export", file, "--csv", (dir / "x.csv").string(), "--namespace", "b"},
       "no rbsim_msgs/msg/SceneDescription topic in namespace 'b'"},
      {{"log", "export", file, "--csv", (dir / "no-dir" / "x.csv").string()}, "no-dir"},
  };
  for (const Case& c : cases) {
    Outcome o = rbsim(c.args);
    EXPECT_EQ(o.exit_code, 1) << describe(o);
    ASSERT_EQ(o.err_lines().size(), 1u) << describe(o);
    EXPECT_EQ(o.err.rfind("rbsim log export: error: ", 0), 0u) << o.err;
    EXPECT_NE(o.err.find(c.needle), std::string::npos) << o.err;
  }
  EXPECT_FALSE(fs::exists(dir / "x.csv"));
  // A recording with a different schema text for one of the types is refused, not misread.
  mcap::Writer w;
  ASSERT_TRUE(
      w.open((dir / "other.mcap").string(), recordings::writer_options(mcap::Compression::Zstd)).ok());
  for (const char* type :
       {"rbsim_msgs/msg/SceneDescription", "rbsim_msgs/msg/BodyStates", "rbsim_msgs/msg/EnergyTerms"}) {
    const auto s = w.add_schema(type, "ros2msg", bytes_of("float64 x"));
    ASSERT_TRUE(s.ok());
    ASSERT_TRUE(w.add_channel(s.value(), std::string("/rbsim/") + type, "cdr").ok());
  }
  ASSERT_TRUE(w.close().ok());
  Outcome o = rbsim({"log", "export", (dir / "other.mcap").string(), "--csv", (dir / "x.csv").string()});
  EXPECT_EQ(o.exit_code, 1) << describe(o);
  EXPECT_NE(o.err.find("schema differs"), std::string::npos) << o.err;
}

TEST(LogCli, HelpForEveryCommand) {
  for (std::vector<std::string> args : {std::vector<std::string>{"log", "--help"},
                                        {"log", "info", "--help"},
                                        {"log", "doctor", "--help"},
                                        {"log", "recover", "--help"},
                                        {"log", "export", "--help"},
                                        {"log", "cat", "--help"},
                                        {"log", "filter", "--help"},
                                        {"log", "merge", "--help"},
                                        {"log", "compress", "--help"}}) {
    Outcome o = rbsim(args, seconds(20));
    EXPECT_EQ(o.exit_code, 0) << describe(o);
    EXPECT_NE(o.out.find("Usage"), std::string::npos) << describe(o);
  }
  Outcome o = rbsim({"log"}, seconds(20));
  EXPECT_NE(o.exit_code, 0);
}

TEST(LogCli, InfoDoctorRecoverOnAGoodRecording) {
  TempDir dir;
  const std::string file = (dir / "r.mcap").string();
  Outcome run =
      rbsim({"run", source_path("scenes/cantilever.xml"), "-q", "--steps", "300", "--record", file});
  ASSERT_EQ(run.exit_code, 0) << describe(run);

  Outcome info = rbsim({"log", "info", file});
  EXPECT_EQ(info.exit_code, 0) << describe(info);
  for (const char* needle : {"profile:     ros2", "messages:    1808", "duration:    0.300000000 s",
                             "compression:", "zstd: [", "/rbsim/body_states", "301 msgs",
                             "rbsim_msgs/msg/BodyStates [ros2msg]", "/clock", "rosgraph_msgs/msg/Clock"}) {
    EXPECT_NE(info.out.find(needle), std::string::npos) << needle << "\n" << info.out;
  }
  EXPECT_TRUE(info.err.empty()) << info.err;

  Outcome doctor = rbsim({"log", "doctor", file});
  EXPECT_EQ(doctor.exit_code, 0) << describe(doctor);
  EXPECT_EQ(doctor.out, "Examining " + file + "\n0 errors, 0 warnings\n");
  EXPECT_TRUE(doctor.err.empty()) << doctor.err;

  Outcome recover = rbsim({"log", "recover", file, (dir / "copy.mcap").string()});
  EXPECT_EQ(recover.exit_code, 0) << describe(recover);
  EXPECT_NE(recover.out.find("kept 1808 messages"), std::string::npos) << recover.out;
  EXPECT_NE(recover.out.find("input intact"), std::string::npos) << recover.out;
  EXPECT_EQ(rbsim({"log", "doctor", (dir / "copy.mcap").string()}).exit_code, 0);
  Outcome same = rbsim({"log", "recover", file, file});
  EXPECT_EQ(same.exit_code, 1);
  EXPECT_NE(same.err.find("is an input of this command; refusing to write over it"), std::string::npos)
      << same.err;
}

// rbsim run --record --topics: exactly the chosen topics (and the scene description), in every
// spelling msgs::names_topic understands; the default set has no PoseArray.
TEST(RecordCli, TopicsChoosesWhatIsRecorded) {
  TempDir dir;
  const std::string scene = source_path("scenes/cantilever.xml");
  const std::string chosen = (dir / "chosen.mcap").string(), all = (dir / "default.mcap").string();
  Outcome run = rbsim({"run", scene, "-q", "--steps", "20", "--record", chosen, "--namespace", "bots",
                       "--topics", "poses,/tf,bots/springs"});
  ASSERT_EQ(run.exit_code, 0) << describe(run);
  Outcome info = rbsim({"log", "info", chosen});
  ASSERT_EQ(info.exit_code, 0) << describe(info);
  for (const char* topic : {"/bots/scene ", "/bots/poses ", "/tf ", "/bots/springs "}) {
    EXPECT_NE(info.out.find(topic), std::string::npos) << topic << "\n" << info.out;
  }
  for (const char* topic : {"/bots/body_states", "/bots/markers", "/clock", "/bots/energy"}) {
    EXPECT_EQ(info.out.find(topic), std::string::npos) << topic << "\n" << info.out;
  }
  EXPECT_NE(info.out.find("messages:    64"), std::string::npos) << info.out;  // 1 + 3 x 21
  run = rbsim({"run", scene, "-q", "--steps", "20", "--record", all});
  ASSERT_EQ(run.exit_code, 0) << describe(run);
  info = rbsim({"log", "info", all});
  EXPECT_EQ(info.out.find("poses"), std::string::npos) << info.out;
  EXPECT_NE(info.out.find("/rbsim/markers        1 msgs"), std::string::npos) << info.out;
  EXPECT_NE(info.out.find("/tf                   21 msgs"), std::string::npos) << info.out;
}

// A recording made before the viewer topics (EnergyTerms without the potential split, per-step
// PoseArray and MarkerArray): every reader still takes it, and export recomputes the split exactly
// as the run's energy CSV has it.
TEST(ReadersCli, RecordingsOfTheFormerLayoutStillRead) {
  TempDir dir;
  const std::string old = data_path("old-format/airplane-before-viewer-topics.mcap");
  const std::string scene = source_path("scenes/airplane.xml");
  Outcome o = rbsim({"log", "export", old, "--energy-csv", (dir / "old.csv").string(), "--csv",
                     (dir / "old-bodies.csv").string()});
  ASSERT_EQ(o.exit_code, 0) << describe(o);
  o = rbsim({"run", scene, "-q", "--energy-csv", (dir / "run.csv").string(), "--csv",
             (dir / "run-bodies.csv").string()});
  ASSERT_EQ(o.exit_code, 0) << describe(o);
  EXPECT_EQ(every_kth_step(read_text(dir / "run.csv"), 100), read_text(dir / "old.csv"));
  EXPECT_EQ(every_kth_step(read_text(dir / "run-bodies.csv"), 100), read_text(dir / "old-bodies.csv"));
  o = rbsim({"check", "--verify-golden", scene, old, "--fosssim-dir", data_path("fosssim")});
  EXPECT_EQ(o.exit_code, 0) << describe(o);
  EXPECT_NE(o.out.find("info markers: the per-step outlines"), std::string::npos) << o.out;
  o = rbsim({"log", "cat", old, "--topics", "energy", "--end", "0.001"});
  EXPECT_EQ(o.exit_code, 0) << describe(o);
  EXPECT_EQ(o.out.find("potential_gravity"), std::string::npos) << o.out;
  o = rbsim({"plot", old, "--out", (dir / "p.png").string()});
  EXPECT_EQ(o.exit_code, 0) << describe(o);
  // The new layout: the split is in the message, and export takes it from there.
  const std::string now = (dir / "now.mcap").string();
  o = rbsim({"run", scene, "-q", "--steps", "300", "--record", now});
  ASSERT_EQ(o.exit_code, 0) << describe(o);
  o = rbsim({"log", "export", now, "--energy-csv", (dir / "now.csv").string()});
  ASSERT_EQ(o.exit_code, 0) << describe(o);
  const std::vector<std::string> run_rows = lines_of(read_text(dir / "run.csv"));
  ASSERT_GT(run_rows.size(), 302u);
  EXPECT_EQ(lines_of(read_text(dir / "now.csv")),
            std::vector<std::string>(run_rows.begin(), run_rows.begin() + 302));
}

// rbsim log cat: one JSON line per message, as many as rbsim log info counts, in log-time order,
// with the values rbsim run wrote to its CSV.
TEST(CatCli, PrintsEveryMessageAsJsonWithTheRecordedValues) {
  TempDir dir;
  const std::string file = (dir / "r.mcap").string(), csv = (dir / "run.csv").string();
  Outcome run = rbsim(
      {"run", source_path("scenes/cantilever.xml"), "-q", "--steps", "40", "--record", file, "--csv", csv});
  ASSERT_EQ(run.exit_code, 0) << describe(run);

  Outcome info = rbsim({"log", "info", file});
  ASSERT_EQ(info.exit_code, 0) << describe(info);
  std::smatch m;
  ASSERT_TRUE(std::regex_search(info.out, m, std::regex("messages: +([0-9]+)"))) << info.out;
  const std::size_t messages = std::stoull(m[1]);

  Outcome cat = rbsim({"log", "cat", file});
  ASSERT_EQ(cat.exit_code, 0) << describe(cat);
  EXPECT_TRUE(cat.err.empty()) << cat.err;
  const std::vector<std::string> lines = lines_of(cat.out);
  ASSERT_EQ(lines.size(), messages);

  // x, y, theta of (step, body) as rbsim run --csv wrote them
  std::map<std::pair<std::uint64_t, std::int64_t>, std::array<double, 3>> expected;
  bool header = true;
  for (const std::string& line : lines_of(read_text(csv))) {
    if (std::exchange(header, false)) continue;
    std::vector<std::string> f;
    std::stringstream ss(line);
    for (std::string cell; std::getline(ss, cell, ',');) f.push_back(cell);
    ASSERT_GE(f.size(), 6u) << line;
    expected[{std::stoull(f[0]), std::stoll(f[2])}] = {std::stod(f[3]), std::stod(f[4]), std::stod(f[5])};
  }
  ASSERT_FALSE(expected.empty());

  std::uint64_t last_time = 0;
  std::size_t body_states = 0, scenes = 0, bodies_checked = 0;
  for (const std::string& line : lines) {
    nlohmann::json j;
    ASSERT_NO_THROW(j = nlohmann::json::parse(line)) << line.substr(0, 300);
    ASSERT_TRUE(j.is_object());
    for (const char* key : {"topic", "sequence", "log_time", "publish_time", "data"})
      ASSERT_TRUE(j.contains(key)) << key << ": " << line.substr(0, 300);
    const std::uint64_t t = j["log_time"].get<std::uint64_t>();
    EXPECT_GE(t, last_time) << "log-time order";
    last_time = t;
    const std::string topic = j["topic"].get<std::string>();
    scenes += topic == "/rbsim/scene";
    if (topic != "/rbsim/body_states") continue;
    ++body_states;
    const nlohmann::json& data = j["data"];
    const std::uint64_t step = data["step"].get<std::uint64_t>();
    EXPECT_EQ(t,
              static_cast<std::uint64_t>(data["header"]["stamp"]["sec"].get<std::int64_t>()) * 1000000000u +
                  data["header"]["stamp"]["nanosec"].get<std::uint64_t>());
    for (const nlohmann::json& b : data["bodies"]) {
      const auto it = expected.find({step, b["id"].get<std::int64_t>()});
      ASSERT_NE(it, expected.end()) << step;
      EXPECT_EQ(b["x"].get<double>(), it->second[0]) << "step " << step;
      EXPECT_EQ(b["y"].get<double>(), it->second[1]) << "step " << step;
      EXPECT_EQ(b["theta"].get<double>(), it->second[2]) << "step " << step;
      ++bodies_checked;
    }
  }
  EXPECT_EQ(scenes, 1u);
  EXPECT_EQ(body_states, 41u);
  EXPECT_EQ(bodies_checked, expected.size());

  // --topics, by its last name or as recorded, and --start/--end in seconds of log time
  Outcome some =
      rbsim({"log", "cat", file, "--topics", "body_states,/clock", "--start", "0.01", "--end", "0.02"});
  ASSERT_EQ(some.exit_code, 0) << describe(some);
  std::size_t clock = 0, states = 0;
  for (const std::string& line : lines_of(some.out)) {
    const nlohmann::json j = nlohmann::json::parse(line);
    const std::string topic = j["topic"].get<std::string>();
    clock += topic == "/clock";
    states += topic == "/rbsim/body_states";
    EXPECT_GE(j["log_time"].get<std::uint64_t>(), 10000000u);
    EXPECT_LT(j["log_time"].get<std::uint64_t>(), 20000000u);
  }
  EXPECT_EQ(states, clock);
  EXPECT_GT(states, 0u);
  EXPECT_EQ(states + clock, lines_of(some.out).size());

  // errors: an unknown topic, an unreadable file (1); a bad option (2)
  Outcome unknown = rbsim({"log", "cat", file, "--topics", "no_such_topic"});
  EXPECT_EQ(unknown.exit_code, 1) << describe(unknown);
  EXPECT_NE(unknown.err.find("rbsim log cat: error: "), std::string::npos) << unknown.err;
  EXPECT_NE(unknown.err.find("no_such_topic"), std::string::npos) << unknown.err;
  Outcome missing = rbsim({"log", "cat", (dir / "missing.mcap").string()});
  EXPECT_EQ(missing.exit_code, 1) << describe(missing);
  write_text(dir / "junk.mcap", "not an mcap file at all");
  EXPECT_EQ(rbsim({"log", "cat", (dir / "junk.mcap").string()}).exit_code, 1);
  EXPECT_EQ(rbsim({"log", "cat", file, "--start", "x"}).exit_code, 2);
}

TEST(LogCli, DoctorReportsPlantedStatisticsError) {
  TempDir dir;
  RecordSpec spec;
  spec.chunk_size = 64 * 1024;
  ASSERT_NO_FATAL_FAILURE(record_scene(source_path("scenes/cantilever.xml"), dir / "r.mcap", 100, spec));
  mcap::Bytes b = read_bytes(dir / "r.mcap");
  const RawRecord& at = find_record(top_level_records(b), mcap::Opcode::Statistics);
  auto stats = std::get<mcap::Statistics>(parse_at(b, at));
  stats.message_count += 5;
  overwrite_record(b, at, stats);
  fix_crcs(b);
  write_bytes(dir / "r.mcap", b);
  Outcome o = rbsim({"log", "doctor", (dir / "r.mcap").string()});
  EXPECT_EQ(o.exit_code, 1) << describe(o);
  EXPECT_NE(o.out.find("error: Statistics has message count 613, but actual number of messages is 608"),
            std::string::npos)
      << o.out;
  ASSERT_EQ(o.err_lines().size(), 1u) << o.err;
  EXPECT_EQ(
      o.err.rfind("rbsim log doctor: error: " + (dir / "r.mcap").string() + ": Statistics has message count",
                  0),
      0u)
      << o.err;
}

// A 150-step cantilever recording in 32 KiB chunks, written to dir/cut.mcap cut off in the middle
// of chunk `k`, as a killed recorder leaves it; its chunks as recorded.
std::vector<ChunkCount> record_cut_inside_chunk(const TempDir& dir, std::size_t k) {
  RecordSpec spec;
  spec.chunk_size = 32 * 1024;
  record_scene(source_path("scenes/cantilever.xml"), dir / "r.mcap", 150, spec);
  const mcap::Bytes b = read_bytes(dir / "r.mcap");
  const auto chunks = chunk_message_counts(dir / "r.mcap");
  const std::uint64_t cut = (chunks.at(k).start + chunks.at(k).end) / 2;
  write_bytes(dir / "cut.mcap", mcap::Bytes(b.begin(), b.begin() + static_cast<std::ptrdiff_t>(cut)));
  return chunks;
}

TEST(LogCli, RecoverTruncatedRecording) {
  TempDir dir;
  std::vector<ChunkCount> chunks;
  ASSERT_NO_FATAL_FAILURE(chunks = record_cut_inside_chunk(dir, 5));  // inside the sixth chunk
  std::uint64_t kept = 0;
  for (int k = 0; k < 5; ++k) kept += chunks[static_cast<std::size_t>(k)].messages;
  Outcome o = rbsim({"log", "recover", (dir / "cut.mcap").string(), (dir / "out.mcap").string()});
  EXPECT_EQ(o.exit_code, 0) << describe(o);  // OUT written: a success, as `mcap recover` has it
  ASSERT_EQ(o.err_lines().size(), 1u) << o.err;
  EXPECT_EQ(o.err.rfind("rbsim log recover: warning: ", 0), 0u) << o.err;
  EXPECT_NE(o.err.find("truncated: the file ends inside a Chunk record at offset " +
                       std::to_string(chunks[5].start)),
            std::string::npos)
      << o.err;
  EXPECT_NE(o.out.find("kept " + std::to_string(kept) + " messages"), std::string::npos) << o.out;
  EXPECT_NE(o.out.find("1 incomplete chunk"), std::string::npos) << o.out;
  Outcome doctor = rbsim({"log", "doctor", (dir / "out.mcap").string()});
  EXPECT_EQ(doctor.exit_code, 0) << describe(doctor);
  Outcome info = rbsim({"log", "info", (dir / "out.mcap").string()});
  EXPECT_EQ(info.exit_code, 0) << describe(info);
  EXPECT_NE(info.out.find("messages:    " + std::to_string(kept)), std::string::npos) << info.out;
}

// `run --record` writes RUN.mcap.tmp.PID and renames it at the end: a finished run leaves only
// RUN.mcap; a killed one leaves no RUN.mcap, only its temporary, which recover saves.
TEST(RecordCli, KilledRunLeavesItsTemporaryForRecover) {
  TempDir dir;
  const std::string scene = source_path("scenes/chain.xml");
  Outcome done = rbsim({"run", scene, "--steps", "10", "--record", (dir / "done.mcap").string()});
  ASSERT_EQ(done.exit_code, 0) << describe(done);
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir.path())) names.push_back(e.path().filename().string());
  EXPECT_EQ(names, std::vector<std::string>{"done.mcap"});

  // Killed (SIGKILL, by the time limit) long before its 50 million steps are done.
  Outcome killed = rbsim({"run", scene, "--steps", "50000000", "--record", (dir / "run.mcap").string()},
                         std::chrono::milliseconds(3000));
  ASSERT_TRUE(killed.timed_out) << describe(killed);
  EXPECT_FALSE(fs::exists(dir / "run.mcap"));
  std::vector<fs::path> temps;
  for (const auto& e : fs::directory_iterator(dir.path())) {
    if (e.path().filename().string().rfind("run.mcap.tmp.", 0) == 0) temps.push_back(e.path());
  }
  ASSERT_EQ(temps.size(), 1u);
  Outcome o = rbsim({"log", "recover", temps[0].string(), (dir / "run.mcap").string()});
  EXPECT_EQ(o.exit_code, 0) << describe(o);
  EXPECT_NE(o.err.find("truncated"), std::string::npos) << o.err;
  Outcome doctor = rbsim({"log", "doctor", (dir / "run.mcap").string()});
  EXPECT_EQ(doctor.exit_code, 0) << describe(doctor);
}

// A file cut inside its first chunk holds no complete message: recover says so, exits 1 and
// writes nothing (an empty recording would only pass the damage on).
TEST(LogCli, RecoverWritesNothingWhenNoMessageIsComplete) {
  TempDir dir;
  ASSERT_NO_FATAL_FAILURE(record_cut_inside_chunk(dir, 0));
  Outcome o = rbsim({"log", "recover", (dir / "cut.mcap").string(), (dir / "out.mcap").string()});
  EXPECT_EQ(o.exit_code, 1) << describe(o);
  EXPECT_NE(o.err.find("no complete message; nothing written"), std::string::npos) << o.err;
  EXPECT_EQ(o.err.find("rbsim log recover rebuilds"), std::string::npos) << "recover must not suggest itself";
  EXPECT_FALSE(fs::exists(dir / "out.mcap"));
}

// Every tool on every kind of bad input: exit status 1, one clear line on stderr, no crash, no
// hang (each run is bounded by a timeout).
TEST(LogCli, EveryToolOnBadInputFailsCleanly) {
  TempDir dir;
  RecordSpec spec;
  spec.chunk_size = 32 * 1024;
  ASSERT_NO_FATAL_FAILURE(record_scene(source_path("scenes/cantilever.xml"), dir / "good.mcap", 100, spec));
  const mcap::Bytes good = read_bytes(dir / "good.mcap");
  const auto records = top_level_records(good);
  const RawRecord& chunk = find_record(records, mcap::Opcode::Chunk, 1);
  const RawRecord& index = find_record(records, mcap::Opcode::MessageIndex, 3);
  const RawRecord& stats = find_record(records, mcap::Opcode::Statistics);
  const RawRecord& footer = find_record(records, mcap::Opcode::Footer);

  std::vector<std::pair<std::string, mcap::Bytes>> inputs;
  inputs.emplace_back("empty", mcap::Bytes{});
  inputs.emplace_back("text", bytes_of("t,x\n0,1\n"));
  inputs.emplace_back("zeros", mcap::Bytes(1000, std::byte{0}));
  inputs.emplace_back("magic_only", mcap::Bytes(std::begin(mcap::kMagic), std::end(mcap::kMagic)));
  for (std::uint64_t cut : {std::uint64_t{3}, std::uint64_t{20}, chunk.offset + 100, index.offset + 3,
                            stats.offset + 10, footer.offset + 5, good.size() - 4}) {
    inputs.emplace_back("cut_" + std::to_string(cut),
                        mcap::Bytes(good.begin(), good.begin() + static_cast<std::ptrdiff_t>(cut)));
  }
  for (std::uint64_t at :
       {std::uint64_t{1}, std::uint64_t{12}, chunk.offset + 4, chunk.offset + chunk.length / 2,
        index.offset + 12, stats.offset + 12, footer.offset + 12, good.size() - 3}) {
    mcap::Bytes b = good;
    b[at] ^= std::byte{0x41};
    inputs.emplace_back("flip_" + std::to_string(at), b);
  }
  {
    mcap::Bytes b(good.begin(), good.begin() + static_cast<std::ptrdiff_t>(chunk.offset + chunk.length + 5));
    b.resize(b.size() + 100'000, std::byte{0});
    inputs.emplace_back("zero_tail", b);
  }
  // A huge length in a record header: must not allocate it or loop.
  {
    mcap::Bytes b = good;
    for (int i = 0; i < 8; ++i) b[chunk.offset + 1 + static_cast<std::uint64_t>(i)] = std::byte{0xFF};
    inputs.emplace_back("huge_length", b);
  }

  const std::regex one_line("rbsim log (info|doctor|recover|export): error: [^\n]+\n");
  const std::regex recovered_line(
      "rbsim log recover: warning: [^\n]+; wrote [^\n]+ complete messages[^\n]*\n");
  for (const auto& [name, bytes] : inputs) {
    const std::string in = (dir / (name + ".mcap")).string();
    write_bytes(in, bytes);
    const std::string out = (dir / (name + "_out.mcap")).string();
    for (std::vector<std::string> args : {std::vector<std::string>{"log", "info", in},
                                          {"log", "doctor", in},
                                          {"log", "recover", in, out},
                                          {"log", "export", in, "--csv", (dir / "x.csv").string(),
                                           "--energy-csv", (dir / "xe.csv").string()}}) {
      Outcome o = rbsim(args, seconds(30));
      SCOPED_TRACE(name + ": rbsim log " + args[1]);
      EXPECT_FALSE(o.timed_out);
      EXPECT_EQ(o.signal, 0);
      if (args[1] == "recover" && fs::exists(out)) {  // saved what was complete: exit 0, a warning
        EXPECT_EQ(o.exit_code, 0) << describe(o);
        EXPECT_TRUE(std::regex_match(o.err, recovered_line)) << describe(o);
      } else {
        EXPECT_EQ(o.exit_code, 1) << describe(o);
        EXPECT_TRUE(std::regex_match(o.err, one_line)) << describe(o);
      }
    }
    EXPECT_FALSE(fs::exists(dir / "x.csv"));
    EXPECT_FALSE(fs::exists(dir / "xe.csv"));
    // recover writes an output exactly when the input has a complete message.
    if (fs::exists(out)) {
      Outcome doctor = rbsim({"log", "doctor", out}, seconds(30));
      EXPECT_EQ(doctor.exit_code, 0) << name << ": recovered file\n" << describe(doctor);
    }
  }
}

// A rosbag2 bag directory (rbsim run --record DIR): metadata.yaml beside DIR_0.mcap, which holds
// the bytes the .mcap output holds; every reader takes the directory as it takes the file.
TEST(LogCli, BagDirectoryIsReadWhereverAFileIs) {
  TempDir dir;
  const std::string scene = source_path("scenes/chain.xml");
  const std::string file = (dir / "run.mcap").string(), bag = (dir / "run").string();
  for (const std::string& out : {file, bag}) {
    const Outcome o = rbsim({"run", scene, "-q", "--steps", "60", "--record", out});
    ASSERT_EQ(o.exit_code, 0) << describe(o);
  }
  EXPECT_EQ(read_text(dir / "run" / "run_0.mcap"), read_text(file))
      << "a bag's file is the .mcap run --record writes";
  const std::string meta = read_text(dir / "run" / "metadata.yaml");
  for (const char* want :
       {"version: 9", "storage_identifier: mcap", "relative_file_paths:\n    - run_0.mcap",
        "message_count: 368", "name: /rbsim/body_states", "type: rbsim_msgs/msg/BodyStates",
        "type_description_hash: RIHS01_", "durability: transient_local", "ros_distro: jazzy"}) {
    EXPECT_NE(meta.find(want), std::string::npos) << want << " in\n" << meta;
  }
  // The same output from the directory as from the file.
  const std::vector<std::vector<std::string>> readers = {{"log", "cat", "@", "--topics", "energy"},
                                                         {"check", "@", file}};
  for (const auto& args : readers) {
    std::vector<std::string> from_file = args, from_bag = args;
    std::replace(from_file.begin(), from_file.end(), std::string("@"), file);
    std::replace(from_bag.begin(), from_bag.end(), std::string("@"), bag);
    const Outcome a = rbsim(from_file), b = rbsim(from_bag);
    EXPECT_EQ(a.exit_code, 0) << describe(a);
    EXPECT_EQ(b.exit_code, 0) << describe(b);
    if (args[0] != "check") {
      EXPECT_EQ(a.out, b.out) << args[0] << " " << args[1];
    }
  }
  for (const std::string& in : {file, bag}) {
    const Outcome o = rbsim({"log", "export", in, "--csv", in + ".csv"});
    EXPECT_EQ(o.exit_code, 0) << describe(o);
  }
  EXPECT_EQ(read_text(bag + ".csv"), read_text(file + ".csv"));
  for (const std::string& in : {file, bag}) {
    const Outcome o = rbsim({"render", in, "--out", in + ".frames", "--fps", "4", "--size", "64x48"});
    EXPECT_EQ(o.exit_code, 0) << describe(o);
  }
  EXPECT_EQ(read_text(fs::path(bag + ".frames") / "frame00001.png"),
            read_text(fs::path(file + ".frames") / "frame00001.png"));
  const Outcome doctor = rbsim({"log", "doctor", bag});
  EXPECT_EQ(doctor.exit_code, 0) << describe(doctor);
  EXPECT_NE(doctor.out.find("Examining " + (fs::path(bag) / "run_0.mcap").string()), std::string::npos)
      << doctor.out;
  const Outcome info = rbsim({"log", "info", bag});
  EXPECT_EQ(info.exit_code, 0) << describe(info);
  EXPECT_NE(info.out.find("(rosbag2, 1 file)"), std::string::npos) << info.out;
  // A directory that is not a bag, and a bag whose file is gone: errors naming them.
  fs::create_directory(dir / "empty");
  Outcome bad = rbsim({"log", "cat", (dir / "empty").string()});
  EXPECT_EQ(bad.exit_code, 1) << describe(bad);
  EXPECT_NE(bad.err.find("without metadata.yaml: not a rosbag2 bag"), std::string::npos) << bad.err;
  fs::remove(dir / "run" / "run_0.mcap");
  bad = rbsim({"check", bag, file});
  EXPECT_NE(bad.exit_code, 0) << describe(bad);
  EXPECT_NE(bad.err.find("run_0.mcap, which is missing"), std::string::npos) << bad.err;
}

}  // namespace
}  // namespace rbsim::test
