// MCAP conformance suite: every X.mcap under test/data/mcap-conformance against its X.json.
// The JSON files hold the *streamed* reader form (every record in file order, chunk contents in
// place of each Chunk, no Chunk/MessageIndex entries). The indexed form is derived from it the way
// foxglove's IndexedReadTestRunner does (tests/conformance/scripts/run-tests/runners/TestRunner.ts).
//
// The .mcap files were rebuilt from their JSON (conformance_gen.cpp) because the MCAP repository keeps
// them as Git LFS pointers; SHA256SUMS keeps the pointers' oids, and OfficialBytes proves each file is the
// official one.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "conformance_gen.hpp"
#include "record_json.hpp"

namespace rbsim::mcap::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::vector<std::string> conformance_files() {
  std::vector<std::string> files;
  for (const auto& entry : fs::recursive_directory_iterator(RBSIM_MCAP_CONFORMANCE_DIR)) {
    if (entry.path().extension() == ".mcap") files.push_back(entry.path().string());
  }
  std::sort(files.begin(), files.end());
  return files;
}

json load_expected(const std::string& mcap_path) {
  std::ifstream in(fs::path(mcap_path).replace_extension(".json"));
  return json::parse(in);
}

std::map<std::string, std::string> official_sha256() {
  std::map<std::string, std::string> sums;  // relative path -> oid
  std::ifstream in(fs::path(RBSIM_MCAP_CONFORMANCE_DIR) / "SHA256SUMS");
  std::string hash, path;
  while (in >> hash >> path) sums[path] = hash;
  return sums;
}

bool has_feature(const json& expected, const std::string& feature) {
  const auto& features = expected["meta"]["variant"]["features"];
  return std::find(features.begin(), features.end(), feature) != features.end();
}

class Conformance : public ::testing::TestWithParam<std::string> {};

TEST_P(Conformance, OfficialBytes) {
  static const auto sums = official_sha256();
  const std::string rel = fs::relative(GetParam(), RBSIM_MCAP_CONFORMANCE_DIR).string();
  ASSERT_EQ(sums.count(rel), 1u) << rel << " missing from SHA256SUMS";
  EXPECT_EQ(sha256_hex(read_file(GetParam())), sums.at(rel))
      << "not the official file (a Git LFS pointer?): rebuild it with generate_conformance_file";
}

// Writer-side check: our record serialisation reproduces the official bytes exactly.
TEST_P(Conformance, RebuiltFromJson) {
  const Bytes rebuilt = generate_conformance_file(load_expected(GetParam()));
  EXPECT_TRUE(rebuilt == read_file(GetParam()));
}

TEST_P(Conformance, StreamedReader) {
  const json expected = load_expected(GetParam());
  StreamReader reader;
  ASSERT_TRUE(reader.open(GetParam()).ok());
  json records = json::array();
  RecordEntry entry;
  while (reader.next(entry)) records.push_back(record_to_json(entry.record));
  ASSERT_TRUE(reader.status().ok()) << reader.status().error().message;
  EXPECT_EQ(records.dump(1), expected["records"].dump(1));
}

// foxglove runs its indexed readers only on files with messages, chunks, chunk and message indexes
// and repeated schemas/channels; ours falls back to a scan elsewhere, so it must match everywhere.
TEST_P(Conformance, IndexedReader) {
  const json file = load_expected(GetParam());
  const json expected = indexed_view_of(file["records"]);
  IndexedReader reader;
  const Status opened = reader.open(GetParam());
  ASSERT_TRUE(opened.ok()) << opened.error().message;
  EXPECT_EQ(reader.indexed(), has_feature(file, "ch") && has_feature(file, "chx"));
  json messages = json::array();
  const Status read = reader.read_messages({}, [&](const MessageEntry& e) {
    messages.push_back(record_to_json(e.message));
    return true;
  });
  ASSERT_TRUE(read.ok()) << read.error().message;
  json schemas = json::array(), channels = json::array(), stats = json::array();
  for (const auto& [id, s] : reader.schemas()) schemas.push_back(record_to_json(s));
  for (const auto& [id, c] : reader.channels()) channels.push_back(record_to_json(c));
  if (reader.statistics()) stats.push_back(record_to_json(*reader.statistics()));
  const json actual{
      {"schemas", schemas}, {"channels", channels}, {"messages", messages}, {"statistics", stats}};
  EXPECT_EQ(actual.dump(1), expected.dump(1));
  EXPECT_TRUE(reader.verify_data_section_crc().ok());
}

std::string case_name(const ::testing::TestParamInfo<std::string>& info) {
  std::string name = fs::path(info.param).stem().string();
  std::replace(name.begin(), name.end(), '-', '_');
  return name;
}

INSTANTIATE_TEST_SUITE_P(Files, Conformance, ::testing::ValuesIn(conformance_files()), case_name);

TEST(ConformanceData, AllFilesPresent) {
  EXPECT_EQ(conformance_files().size(), 416u);
}

}  // namespace
}  // namespace rbsim::mcap::test
