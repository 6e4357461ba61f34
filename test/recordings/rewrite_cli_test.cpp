// rbsim log filter | merge | compress and log cat --format csv through the real binary
// (subprocess, time-bounded): each output passes rbsim log doctor and rbsim check against its
// source for what it kept; outputs are refused as every other command refuses them.
#include <gtest/gtest.h>

#include <regex>
#include <tuple>

#include "rbsim/subprocess.hpp"
#include "recordings_test_util.hpp"

namespace rbsim::test {
namespace {

namespace fs = std::filesystem;

std::string describe(const Outcome& o) {
  return "exit " + std::to_string(o.exit_code) + (o.timed_out ? " (timed out)" : "") + "\nstdout:\n" +
         o.out.substr(0, 3000) + "\nstderr:\n" + o.err.substr(0, 3000);
}

std::string record(const TempDir& dir, const std::string& name, const std::string& scene,
                   std::vector<std::string> extra = {}) {
  const std::string file = (dir / name).string();
  std::vector<std::string> args = {"run", source_path("scenes/" + scene), "-q", "--record", file};
  args.insert(args.end(), extra.begin(), extra.end());
  Outcome run = rbsim(args);
  EXPECT_EQ(run.exit_code, 0) << describe(run);
  return file;
}

void expect_doctor_clean(const std::string& file) {
  Outcome doctor = rbsim({"log", "doctor", "--strict-message-order", file});
  EXPECT_EQ(doctor.exit_code, 0) << describe(doctor);
  EXPECT_NE(doctor.out.find("0 errors, 0 warnings"), std::string::npos) << doctor.out;
}

// "  (3) /rbsim/body_states    500 msgs ..." -> 500, from rbsim log info; -1 when not listed.
long long info_count(const std::string& info, const std::string& topic) {
  std::smatch m;
  if (!std::regex_search(info, m, std::regex("\\) +" + topic + " +([0-9]+) msgs"))) return -1;
  return std::stoll(m[1]);
}

// The lines of `csv` (rbsim log export --csv) whose step is in [first, last], header included.
std::string steps_of(const std::string& csv, long long first, long long last) {
  std::string out;
  bool header = true;
  for (const std::string& line : lines_of(csv)) {
    if (header) {
      out += line + "\n";
      header = false;
      continue;
    }
    const long long step = std::stoll(line.substr(0, line.find(',')));
    if (step >= first && step <= last) out += line + "\n";
  }
  return out;
}

TEST(LogFilter, WindowStartingMidRunRendersAndChecksOnItsOwn) {
  TempDir dir;
  const std::string in = record(dir, "in.mcap", "cantilever.xml", {"--steps", "1000"});
  const std::string slice = (dir / "slice.mcap").string();
  Outcome filter = rbsim({"log", "filter", in, slice, "--start", "0.3", "--end", "0.6"});
  ASSERT_EQ(filter.exit_code, 0) << describe(filter);
  EXPECT_NE(filter.out.find("(2 latched from before the window)"), std::string::npos) << filter.out;
  expect_doctor_clean(slice);

  Outcome info = rbsim({"log", "info", slice});
  ASSERT_EQ(info.exit_code, 0) << describe(info);
  EXPECT_EQ(info_count(info.out, "/rbsim/scene"), 1) << info.out;
  EXPECT_EQ(info_count(info.out, "/rbsim/markers"), 1) << info.out;
  for (const char* topic : {"/rbsim/body_states", "/rbsim/energy", "/tf", "/clock"})
    EXPECT_EQ(info_count(info.out, topic), 300) << topic << "\n" << info.out;  // steps 300..599

  // Read as a recording of its own: the steps it kept, value for value those of its source.
  const fs::path in_csv = dir / "in.csv", slice_csv = dir / "slice.csv";
  ASSERT_EQ(rbsim({"log", "export", in, "-q", "--csv", in_csv.string()}).exit_code, 0);
  Outcome exp = rbsim({"log", "export", slice, "-q", "--csv", slice_csv.string()});
  ASSERT_EQ(exp.exit_code, 0) << describe(exp);
  EXPECT_EQ(read_text(slice_csv), steps_of(read_text(in_csv), 300, 599));
  Outcome render = rbsim({"render", slice, "--out", (dir / "frames").string(), "--fps", "10"});
  ASSERT_EQ(render.exit_code, 0) << describe(render);
  EXPECT_GE(std::distance(fs::directory_iterator(dir / "frames"), fs::directory_iterator{}), 3);

  // rbsim check against the source: the latched topics match; every kept message is identical and
  // only the steps outside the window are missing.
  Outcome latched = rbsim({"check", slice, in, "--topics", "scene,markers"});
  EXPECT_EQ(latched.exit_code, 0) << describe(latched);
  Outcome all = rbsim({"check", slice, in});
  EXPECT_EQ(all.exit_code, 1) << describe(all);
  EXPECT_NE(all.out.find("identical"), std::string::npos) << all.out;
  EXPECT_EQ(all.out.find("max error:"), std::string::npos) << all.out;
  EXPECT_NE(all.out.find("/rbsim/body_states: run lacks steps 0..299, 600..1000"), std::string::npos)
      << all.out;
}

// Chunks inside the window are copied as stored: the same messages as a filter that writes every
// chunk anew (another codec), and a copied chunk that is damaged fails the filter, writing nothing.
TEST(LogFilter, CopiesWholeChunksAndChecksThem) {
  TempDir dir;
  const std::string run = record(dir, "run.mcap", "cantilever.xml", {"--steps", "1000"});
  const std::string in = (dir / "in.mcap").string();  // ~80 chunks
  ASSERT_EQ(rbsim({"log", "compress", run, in, "--chunk-size", "50000"}).exit_code, 0);
  const std::string copied = (dir / "copied.mcap").string(), anew = (dir / "anew.mcap").string();
  Outcome filter = rbsim({"log", "filter", in, copied, "--start", "0.2", "--end", "0.8"});
  ASSERT_EQ(filter.exit_code, 0) << describe(filter);
  std::smatch m;
  ASSERT_TRUE(std::regex_search(filter.out, m, std::regex("; ([0-9]+) chunks copied whole"))) << filter.out;
  EXPECT_GT(std::stoi(m[1]), 20) << filter.out;
  expect_doctor_clean(copied);
  ASSERT_EQ(
      rbsim({"log", "filter", in, anew, "--start", "0.2", "--end", "0.8", "--compression", "lz4"}).exit_code,
      0);
  EXPECT_EQ(rbsim({"log", "cat", copied}).out, rbsim({"log", "cat", anew}).out);
  EXPECT_EQ(rbsim({"check", copied, anew, "--strict-metadata"}).exit_code, 0);

  // A byte of one chunk's compressed records flipped: the middle one, then its neighbour (the
  // copied chunks' checks alternate between two threads: each is caught).
  const mcap::Bytes original = read_bytes(in);
  const auto records = top_level_records(original);
  std::size_t chunks = 0;
  for (const RawRecord& r : records) chunks += r.opcode == static_cast<std::uint8_t>(mcap::Opcode::Chunk);
  for (const std::size_t k : {chunks / 2, chunks / 2 + 1}) {
    mcap::Bytes bytes = original;
    const RawRecord chunk = find_record(records, mcap::Opcode::Chunk, k);
    bytes[chunk.offset + chunk.length - 100] ^= std::byte{0x55};
    const std::string damaged = (dir / "damaged.mcap").string(), out = (dir / "out.mcap").string();
    write_bytes(damaged, bytes);
    Outcome bad = rbsim({"log", "filter", damaged, out, "--start", "0.2", "--end", "0.8"});
    EXPECT_EQ(bad.exit_code, 1) << describe(bad);
    EXPECT_NE(bad.err.find(damaged + ": chunk at offset " + std::to_string(chunk.offset)), std::string::npos)
        << bad.err;
    EXPECT_FALSE(fs::exists(out));
  }
}

TEST(LogFilter, TopicsKeepsAndExcludeTopicsLeavesOut) {
  TempDir dir;
  const std::string in = record(dir, "in.mcap", "chain.xml", {"--steps", "200"});
  const std::string kept = (dir / "kept.mcap").string(), left = (dir / "left.mcap").string();
  Outcome keep = rbsim({"log", "filter", in, kept, "--topics", "body_states,/rbsim/scene"});
  ASSERT_EQ(keep.exit_code, 0) << describe(keep);
  expect_doctor_clean(kept);
  Outcome info = rbsim({"log", "info", kept});
  EXPECT_EQ(info_count(info.out, "/rbsim/body_states"), 201) << info.out;
  EXPECT_EQ(info_count(info.out, "/rbsim/scene"), 1) << info.out;
  EXPECT_EQ(info_count(info.out, "/rbsim/energy"), -1) << info.out;
  EXPECT_EQ(rbsim({"check", kept, in, "--topics", "body_states,scene"}).exit_code, 0);

  Outcome leave = rbsim({"log", "filter", in, left, "--exclude-topics", "tf,clock"});
  ASSERT_EQ(leave.exit_code, 0) << describe(leave);
  expect_doctor_clean(left);
  info = rbsim({"log", "info", left});
  EXPECT_EQ(info_count(info.out, "/tf"), -1) << info.out;
  EXPECT_EQ(info_count(info.out, "/clock"), -1) << info.out;
  EXPECT_EQ(info_count(info.out, "/rbsim/spring_states"), 201) << info.out;
  Outcome check = rbsim({"check", left, in, "--exclude-topics", "tf,clock"});
  EXPECT_EQ(check.exit_code, 0) << describe(check);
}

TEST(LogFilter, TopicsWithoutMessagesInTheWindowAreListed) {
  TempDir dir;
  // Every 100th step: no per-step message between 0.31 s and 0.39 s.
  const std::string in = record(dir, "in.mcap", "chain.xml", {"--steps", "500", "--record-every", "100"});
  const std::string out = (dir / "out.mcap").string();
  Outcome filter = rbsim({"log", "filter", in, out, "--start", "0.31", "--end", "0.39"});
  ASSERT_EQ(filter.exit_code, 0) << describe(filter);
  expect_doctor_clean(out);
  Outcome info = rbsim({"log", "info", out});
  EXPECT_EQ(info_count(info.out, "/rbsim/scene"), 1) << info.out;
  for (const char* topic : {"/rbsim/body_states", "/rbsim/spring_states", "/rbsim/energy", "/tf", "/clock"})
    EXPECT_EQ(info_count(info.out, topic), 0) << topic << "\n" << info.out;
}

TEST(LogFilter, RefusesWhatItMustNotWrite) {
  TempDir dir;
  const std::string in = record(dir, "in.mcap", "chain.xml", {"--steps", "50"});
  const std::string out = (dir / "out.mcap").string();
  write_text(out, "keep me");
  Outcome exists = rbsim({"log", "filter", in, out});
  EXPECT_EQ(exists.exit_code, 1) << describe(exists);
  EXPECT_NE(exists.err.find(out), std::string::npos) << exists.err;
  EXPECT_EQ(read_text(out), "keep me");
  Outcome over = rbsim({"log", "filter", in, out, "--overwrite", "--end", "0.01"});
  EXPECT_EQ(over.exit_code, 0) << describe(over);
  expect_doctor_clean(out);
  Outcome self = rbsim({"log", "filter", in, in, "--overwrite"});
  EXPECT_EQ(self.exit_code, 1) << describe(self);

  const std::string none = (dir / "none.mcap").string();
  Outcome unknown = rbsim({"log", "filter", in, none, "--topics", "nosuch"});
  EXPECT_EQ(unknown.exit_code, 1) << describe(unknown);
  EXPECT_NE(unknown.err.find(in + ": unknown topic \"nosuch\" (topics: "), std::string::npos) << unknown.err;
  EXPECT_EQ(rbsim({"log", "filter", in, none, "--start", "2", "--end", "1"}).exit_code, 2);
  EXPECT_EQ(rbsim({"log", "filter", in, none, "--topics", "tf", "--exclude-topics", "clock"}).exit_code, 2);
  EXPECT_FALSE(fs::exists(none));
  for (const auto& e : fs::directory_iterator(dir.path()))
    EXPECT_EQ(e.path().string().find(".tmp."), std::string::npos) << e.path();
}

TEST(LogMerge, TwoNodesInLogTimeOrderEqualTimesInInputOrder) {
  TempDir dir;
  const std::string a = record(dir, "a.mcap", "cantilever.xml", {"--steps", "300", "--namespace", "a"});
  const std::string b =
      record(dir, "b.mcap", "chain.xml", {"--steps", "400", "--namespace", "b", "--record-every", "3"});
  const std::string out = (dir / "m.mcap").string();
  Outcome merge = rbsim({"log", "merge", a, b, out});
  ASSERT_EQ(merge.exit_code, 0) << describe(merge);
  expect_doctor_clean(out);  // --strict-message-order: log-time order
  // /tf and /clock of both nodes share one channel each; the rest are two nodes' own.
  EXPECT_NE(merge.out.find("on 14 topics, 14 channels, 8 schemas"), std::string::npos) << merge.out;

  Outcome cat = rbsim({"log", "cat", out, "--topics", "a/body_states,b/body_states"});
  ASSERT_EQ(cat.exit_code, 0) << describe(cat);
  std::string order;  // which node each body_states message at log time 0.003 s came from
  for (const std::string& line : lines_of(cat.out)) {
    if (line.find("\"log_time\":3000000,") != std::string::npos)
      order += line.find("/a/") != std::string::npos ? 'a' : 'b';
  }
  EXPECT_EQ(order, "ab");
  Outcome swapped = rbsim({"log", "merge", b, a, (dir / "ba.mcap").string()});
  ASSERT_EQ(swapped.exit_code, 0) << describe(swapped);
  cat = rbsim({"log", "cat", (dir / "ba.mcap").string(), "--topics", "a/body_states,b/body_states", "--start",
               "0.003", "--end", "0.0031"});
  EXPECT_NE(cat.out.find("/b/body_states"), std::string::npos);
  EXPECT_LT(cat.out.find("/b/body_states"), cat.out.find("/a/body_states")) << cat.out;

  // Each node's topics, filtered back out of the merge, are its recording's, message for message
  // (/tf and /clock hold both nodes' messages).
  for (const auto& [node, other, file] : {std::tuple{"a", "b", a}, std::tuple{"b", "a", b}}) {
    const std::string back = (dir / (std::string(node) + "_back.mcap")).string();
    const std::string o = std::string("/") + other;
    Outcome f = rbsim({"log", "filter", out, back, "--exclude-topics",
                       o + "/scene," + o + "/markers," + o + "/body_states," + o + "/spring_states," + o +
                           "/energy," + o + "/springs"});
    ASSERT_EQ(f.exit_code, 0) << describe(f);
    Outcome check = rbsim({"check", back, file, "--exclude-topics", "tf,clock"});
    EXPECT_EQ(check.exit_code, 0) << describe(check);
    EXPECT_NE(check.out.find("6 topics"), std::string::npos) << check.out;
  }
}

TEST(LogMerge, DifferentScenesRefusedUnlessNamespacesMoveThemApart) {
  TempDir dir;
  const std::string a = record(dir, "a.mcap", "cantilever.xml", {"--steps", "100"});
  const std::string b = record(dir, "b.mcap", "chain.xml", {"--steps", "100"});
  const std::string out = (dir / "m.mcap").string();
  Outcome refused = rbsim({"log", "merge", a, b, out});
  EXPECT_EQ(refused.exit_code, 1) << describe(refused);
  EXPECT_NE(refused.err.find(a + " and " + b + " record different scenes on /rbsim/scene"), std::string::npos)
      << refused.err;
  EXPECT_FALSE(fs::exists(out));
  EXPECT_EQ(rbsim({"log", "merge", a, b, out, "--namespaces", "/one"}).exit_code, 2);
  Outcome bad = rbsim({"log", "merge", a, b, out, "--namespaces", "/one,2two"});
  EXPECT_EQ(bad.exit_code, 2) << describe(bad);
  EXPECT_NE(bad.err.find("\"2two\" is not a ROS 2 namespace"), std::string::npos) << bad.err;

  Outcome apart = rbsim({"log", "merge", a, b, out, "--namespaces", "/one,/two"});
  ASSERT_EQ(apart.exit_code, 0) << describe(apart);
  expect_doctor_clean(out);
  Outcome info = rbsim({"log", "info", out});
  EXPECT_EQ(info_count(info.out, "/one/rbsim/body_states"), 101) << info.out;
  EXPECT_EQ(info_count(info.out, "/two/rbsim/body_states"), 101) << info.out;
  Outcome exp =
      rbsim({"log", "export", out, "-q", "--namespace", "/two/rbsim", "--csv", (dir / "two.csv").string()});
  ASSERT_EQ(exp.exit_code, 0) << describe(exp);
  ASSERT_EQ(rbsim({"log", "export", b, "-q", "--csv", (dir / "b.csv").string()}).exit_code, 0);
  EXPECT_EQ(read_text(dir / "two.csv"), read_text(dir / "b.csv"));

  // The same scene twice (one run, sliced in two): nothing to refuse, one channel per topic.
  const std::string first = (dir / "first.mcap").string(), second = (dir / "second.mcap").string();
  ASSERT_EQ(rbsim({"log", "filter", a, first, "--end", "0.05"}).exit_code, 0);
  ASSERT_EQ(rbsim({"log", "filter", a, second, "--start", "0.05"}).exit_code, 0);
  Outcome whole = rbsim({"log", "merge", first, second, (dir / "whole.mcap").string()});
  ASSERT_EQ(whole.exit_code, 0) << describe(whole);
  EXPECT_NE(whole.out.find("8 channels, 8 schemas"), std::string::npos) << whole.out;
}

TEST(LogCompress, SameMessagesAnotherCodecAndChunking) {
  TempDir dir;
  const std::string in = record(dir, "in.mcap", "cantilever.xml", {"--steps", "600"});
  for (const char* codec : {"lz4", "none", "zstd"}) {
    const std::string out = (dir / (std::string(codec) + ".mcap")).string();
    Outcome c = rbsim({"log", "compress", in, out, "--compression", codec, "--chunk-size", "100000"});
    ASSERT_EQ(c.exit_code, 0) << describe(c);
    expect_doctor_clean(out);
    Outcome info = rbsim({"log", "info", out});
    if (std::string(codec) != "none") {
      EXPECT_NE(info.out.find(std::string(codec) + ": ["), std::string::npos) << info.out;
    }
    std::smatch m;
    ASSERT_TRUE(std::regex_search(info.out, m, std::regex("chunks: +([0-9]+)"))) << info.out;
    EXPECT_GT(std::stoi(m[1]), 10) << info.out;  // ~4.7 MB of messages in 100 kB chunks
    Outcome check = rbsim({"check", out, in, "--strict-metadata"});
    EXPECT_EQ(check.exit_code, 0) << describe(check);
    EXPECT_EQ(rbsim({"log", "cat", out}).out, rbsim({"log", "cat", in}).out);
  }
}

TEST(LogCat, CsvPrintsOneTopicWithColumnsFromItsFlattenedFields) {
  TempDir dir;
  const std::string in = record(dir, "in.mcap", "chain.xml", {"--steps", "20"});
  Outcome csv = rbsim({"log", "cat", in, "--format", "csv", "--topics", "body_states"});
  ASSERT_EQ(csv.exit_code, 0) << describe(csv);
  const std::vector<std::string> lines = lines_of(csv.out);
  ASSERT_EQ(lines.size(), 22u);  // header and steps 0..20
  EXPECT_EQ(lines[0].rfind("log_time,publish_time,sequence,", 0), 0u) << lines[0];
  EXPECT_NE(lines[0].find(",bodies[0].x,"), std::string::npos) << lines[0];
  EXPECT_NE(lines[0].find(",bodies[4].omega"), std::string::npos) << lines[0];
  EXPECT_NE(lines[0].find(",bodies.length,"), std::string::npos) << lines[0];
  EXPECT_EQ(lines[2].rfind("1000000,1000000,1,", 0), 0u) << lines[2];
  const auto columns = [](const std::string& l) { return std::count(l.begin(), l.end(), ','); };
  for (const std::string& line : lines) EXPECT_EQ(columns(line), columns(lines[0])) << line;

  // Step 20's x of body 0 as log export prints it.
  const fs::path export_csv = dir / "e.csv";
  ASSERT_EQ(rbsim({"log", "export", in, "-q", "--csv", export_csv.string()}).exit_code, 0);
  std::string x;
  for (const std::string& line : lines_of(read_text(export_csv)))
    if (line.rfind("20,", 0) == 0 && line.find(",0,") != std::string::npos && x.empty()) x = line;
  ASSERT_FALSE(x.empty());
  std::vector<std::string> f;
  for (std::size_t p = 0, q; p != std::string::npos; p = q == std::string::npos ? q : q + 1) {
    q = x.find(',', p);
    f.push_back(x.substr(p, q == std::string::npos ? q : q - p));
  }
  EXPECT_NE(lines[21].find("," + f[3] + ","), std::string::npos) << lines[21] << " vs x " << f[3];

  Outcome several = rbsim({"log", "cat", in, "--format", "csv"});
  EXPECT_EQ(several.exit_code, 1) << describe(several);
  EXPECT_NE(several.err.find("CSV prints one topic at a time"), std::string::npos) << several.err;
  EXPECT_EQ(rbsim({"log", "cat", in, "--format", "xml"}).exit_code, 2);
  Outcome json = rbsim({"log", "cat", in, "--topics", "energy"});  // json stays the default
  ASSERT_EQ(json.exit_code, 0);
  EXPECT_EQ(json.out.rfind("{\"topic\":\"/rbsim/energy\"", 0), 0u) << json.out.substr(0, 200);
}

}  // namespace
}  // namespace rbsim::test
