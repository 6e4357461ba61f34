// mcap_tools::recover at library level: truncation at many offsets keeps exactly the messages of the
// complete chunks (counted independently, from the original's chunk and message indexes), and
// the output is a clean, indexed file holding those messages unchanged.
#include <gtest/gtest.h>

#include "rbsim/subprocess.hpp"
#include "recordings_test_util.hpp"

namespace rbsim::test {
namespace {

namespace fs = std::filesystem;

std::vector<mcap::Message> all_messages(const fs::path& path) {
  mcap::IndexedReader r;
  EXPECT_TRUE(r.open(path.string()).ok());
  auto m = r.read_all_messages();
  EXPECT_TRUE(m.ok()) << m.error().message;
  return m.ok() ? std::move(m).value() : std::vector<mcap::Message>{};
}

bool same(const mcap::Message& a, const mcap::Message& b) {
  return a.channel_id == b.channel_id && a.sequence == b.sequence && a.log_time == b.log_time &&
         a.publish_time == b.publish_time && a.data == b.data;
}

class RecoverTest : public ::testing::Test {
 protected:
  void SetUp() override {
    RecordSpec spec;
    spec.chunk_size = 32 * 1024;
    ASSERT_NO_FATAL_FAILURE(record_scene(source_path("scenes/cantilever.xml"), original_, 150, spec));
    bytes_ = read_bytes(original_);
    chunks_ = chunk_message_counts(original_);
    messages_ = all_messages(original_);
    ASSERT_GE(chunks_.size(), 10u);
    std::uint64_t total = 0;
    for (const auto& c : chunks_) total += c.messages;
    ASSERT_EQ(total, messages_.size());
    header_end_ = top_level_records(bytes_).front().offset + top_level_records(bytes_).front().length;
  }

  // Messages of the chunks wholly inside the first `cut` bytes, and whether `cut` falls in a chunk.
  std::pair<std::uint64_t, bool> expected(std::uint64_t cut) const {
    std::uint64_t n = 0;
    bool inside = false;
    for (const auto& c : chunks_) {
      if (c.end <= cut) n += c.messages;
      if (c.start < cut && cut < c.end) inside = true;
    }
    return {n, inside};
  }

  void check_recovered(std::uint64_t kept) {
    const auto doc = mcap_tools::doctor(recovered_.string());
    EXPECT_EQ(doc.errors, 0u) << doc.first_error();
    EXPECT_EQ(doc.warnings, 0u);
    const auto got = all_messages(recovered_);
    ASSERT_EQ(got.size(), kept);
    for (std::size_t i = 0; i < got.size(); ++i) ASSERT_TRUE(same(got[i], messages_[i])) << "message " << i;
    mcap::IndexedReader r;
    ASSERT_TRUE(r.open(recovered_.string()).ok());
    EXPECT_TRUE(r.indexed() || kept == 0);
    EXPECT_EQ(r.header().profile, "ros2");
    EXPECT_EQ(r.header().library, "rbsim 0.1.0");
    ASSERT_TRUE(r.statistics().has_value());
    EXPECT_EQ(r.statistics()->message_count, kept);
  }

  TempDir dir_;
  fs::path original_ = dir_ / "original.mcap", cut_ = dir_ / "cut.mcap", recovered_ = dir_ / "recovered.mcap";
  mcap::Bytes bytes_;
  std::vector<ChunkCount> chunks_;
  std::vector<mcap::Message> messages_;
  std::uint64_t header_end_ = 0;
};

TEST_F(RecoverTest, IntactInputIsCopiedWhole) {
  const auto r = mcap_tools::recover(original_.string(), recovered_.string());
  ASSERT_TRUE(r.ok()) << r.error().message;
  EXPECT_TRUE(r.value().input_intact);
  EXPECT_EQ(r.value().messages, messages_.size());
  EXPECT_EQ(r.value().chunks, chunks_.size());
  EXPECT_EQ(r.value().schemas, 8u);
  EXPECT_EQ(r.value().channels, 8u);
  EXPECT_EQ(r.value().incomplete_chunks + r.value().corrupt_chunks + r.value().dropped_messages, 0u);
  check_recovered(messages_.size());
}

TEST_F(RecoverTest, TruncatedAtManyOffsetsKeepsExactlyTheCompleteChunks) {
  std::vector<std::uint64_t> cuts;
  for (int k = 0; k <= 50; ++k) cuts.push_back(bytes_.size() * static_cast<std::uint64_t>(k) / 50);
  const auto& last = chunks_.back();
  for (std::uint64_t c :
       {last.start, last.start + 5, last.start + 9, last.start + 30, (last.start + last.end) / 2,
        last.end - 1, last.end, last.end + 1, header_end_ - 1, header_end_, header_end_ + 1}) {
    cuts.push_back(c);
  }
  for (const auto& c : chunks_) cuts.push_back(c.end);  // exactly at each chunk's end: nothing lost
  for (std::uint64_t cut : cuts) {
    SCOPED_TRACE("cut at " + std::to_string(cut) + " of " + std::to_string(bytes_.size()));
    write_bytes(cut_, mcap::Bytes(bytes_.begin(), bytes_.begin() + static_cast<std::ptrdiff_t>(cut)));
    fs::remove(recovered_);
    const auto r = mcap_tools::recover(cut_.string(), recovered_.string());
    const auto [kept, inside] = expected(cut);
    // Nothing complete to keep (cut inside the header or the first chunk): nothing written.
    if (cut < header_end_ || kept == 0) {
      ASSERT_FALSE(r.ok());
      EXPECT_FALSE(fs::exists(recovered_));
      continue;
    }
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(r.value().messages, kept);
    EXPECT_EQ(r.value().incomplete_chunks, inside ? 1u : 0u);
    EXPECT_EQ(r.value().input_intact, cut == bytes_.size());
    EXPECT_EQ(r.value().dropped_messages, 0u);
    if (cut < bytes_.size()) {
      EXPECT_NE(r.value().problem.find("truncated"), std::string::npos) << r.value().problem;
    }
    ASSERT_NO_FATAL_FAILURE(check_recovered(kept));
  }
}

TEST_F(RecoverTest, CorruptChunkIsSkippedAndTheRestKept) {
  for (std::size_t k : {std::size_t{0}, std::size_t{3}, chunks_.size() - 1}) {
    SCOPED_TRACE("chunk " + std::to_string(k));
    mcap::Bytes b = bytes_;
    b[(chunks_[k].start + chunks_[k].end) / 2] ^= std::byte{0x20};
    write_bytes(cut_, b);
    const auto r = mcap_tools::recover(cut_.string(), recovered_.string());
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_FALSE(r.value().input_intact);
    EXPECT_EQ(r.value().corrupt_chunks, 1u);
    EXPECT_EQ(r.value().messages, messages_.size() - chunks_[k].messages);
    EXPECT_EQ(r.value().dropped_messages, 0u);  // channels lost with chunk 0 come back from the summary
    const auto doc = mcap_tools::doctor(recovered_.string());
    EXPECT_EQ(doc.errors, 0u) << doc.first_error();
  }
}

// A writer that died with its file preallocated leaves zeros after the last complete chunk.
TEST_F(RecoverTest, ZeroFilledTailStopsReadingThere) {
  const auto& c = chunks_[chunks_.size() / 2];
  mcap::Bytes b(bytes_.begin(), bytes_.begin() + static_cast<std::ptrdiff_t>(c.end + 10));
  b.resize(b.size() + 1'000'000, std::byte{0});
  write_bytes(cut_, b);
  const auto r = mcap_tools::recover(cut_.string(), recovered_.string());
  ASSERT_TRUE(r.ok()) << r.error().message;
  EXPECT_FALSE(r.value().input_intact);
  EXPECT_NE(r.value().problem.find("opcode 0x00"), std::string::npos) << r.value().problem;
  EXPECT_EQ(r.value().messages, expected(c.end).first);
  ASSERT_NO_FATAL_FAILURE(check_recovered(expected(c.end).first));
  const auto doc = mcap_tools::doctor(cut_.string());
  EXPECT_EQ(doc.errors, 1u);
  EXPECT_NE(doc.first_error().find("zero-filled"), std::string::npos) << doc.first_error();
}

TEST_F(RecoverTest, RefusesToOverwriteItsInput) {
  const auto size = fs::file_size(original_);
  auto r = mcap_tools::recover(original_.string(), original_.string());
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("must not be the input"), std::string::npos) << r.error().message;
  fs::create_symlink(original_, dir_ / "link.mcap");
  r = mcap_tools::recover(original_.string(), (dir_ / "link.mcap").string());
  ASSERT_FALSE(r.ok());
  r = mcap_tools::recover(original_.string(), (dir_.path() / "." / "original.mcap").string());
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(fs::file_size(original_), size);
  EXPECT_EQ(read_bytes(original_), bytes_);
}

TEST_F(RecoverTest, NothingWrittenForUnreadableInput) {
  for (const mcap::Bytes& b : {mcap::Bytes{}, bytes_of("hello"), mcap::Bytes(4096, std::byte{0})}) {
    write_bytes(cut_, b);
    const auto r = mcap_tools::recover(cut_.string(), recovered_.string());
    EXPECT_FALSE(r.ok());
    EXPECT_FALSE(fs::exists(recovered_));
  }
  EXPECT_FALSE(mcap_tools::recover((dir_ / "missing.mcap").string(), recovered_.string()).ok());
  EXPECT_FALSE(mcap_tools::recover(original_.string(), (dir_ / "no-such-dir" / "x.mcap").string()).ok());
  for (const auto& e : fs::directory_iterator(dir_.path())) {
    EXPECT_EQ(e.path().filename().string().find(".tmp."), std::string::npos)
        << "temporary left behind: " << e.path();
  }
}

// A recovered recording exports to the CSV rows of its complete steps.
TEST_F(RecoverTest, RecoveredRecordingExportsItsCompleteSteps) {
  RecordSpec spec;
  spec.chunk_size = 32 * 1024;
  spec.csv = dir_ / "run.csv";
  spec.energy_csv = dir_ / "run_energy.csv";
  ASSERT_NO_FATAL_FAILURE(record_scene(source_path("scenes/cantilever.xml"), original_, 150, spec));
  bytes_ = read_bytes(original_);
  write_bytes(
      cut_, mcap::Bytes(bytes_.begin(), bytes_.begin() + static_cast<std::ptrdiff_t>(bytes_.size() * 2 / 3)));
  ASSERT_TRUE(mcap_tools::recover(cut_.string(), recovered_.string()).ok());
  recordings::ExportOptions eo;
  eo.csv = (dir_ / "x.csv").string();
  eo.energy_csv = (dir_ / "x_energy.csv").string();
  const auto r = recordings::export_csv(recovered_.string(), eo);
  ASSERT_TRUE(r.ok()) << r.error().message;
  EXPECT_EQ(r.value().first_step, 0u);
  EXPECT_GT(r.value().last_step, 10u);
  EXPECT_LT(r.value().last_step, 150u);
  const auto full = lines_of(read_text(dir_ / "run_energy.csv"));
  const auto got = lines_of(read_text(dir_ / "x_energy.csv"));
  ASSERT_EQ(got.size(), r.value().last_step + 2);
  for (std::size_t i = 0; i < got.size(); ++i) EXPECT_EQ(got[i], full[i]);
  const std::string csv = read_text(dir_ / "x.csv");
  EXPECT_EQ(csv, read_text(dir_ / "run.csv").substr(0, csv.size()));
}

}  // namespace
}  // namespace rbsim::test
