// mcap_tools::doctor at library level: a clean recording, then one planted problem per test (with the
// file's CRCs recomputed, so the planted problem is the one reported), hostile inputs, and the
// official conformance files.
#include <gtest/gtest.h>

#include <functional>
#include <regex>

#include "rbsim/subprocess.hpp"
#include "recordings_test_util.hpp"

namespace rbsim::test {
namespace {

namespace fs = std::filesystem;

bool has_finding(const mcap_tools::DoctorReport& r, const std::string& needle, bool error = true) {
  for (const auto& f : r.findings) {
    if (f.error == error && f.text.find(needle) != std::string::npos) return true;
  }
  return false;
}

std::string dump(const mcap_tools::DoctorReport& r) {
  std::string s = std::to_string(r.errors) + " errors, " + std::to_string(r.warnings) + " warnings\n";
  for (const auto& f : r.findings) s += (f.error ? "error: " : "warning: ") + f.text + "\n";
  return s;
}

class DoctorTest : public ::testing::Test {
 protected:
  void SetUp() override {
    RecordSpec spec;
    spec.chunk_size = 64 * 1024;
    ASSERT_NO_FATAL_FAILURE(record_scene(source_path("scenes/cantilever.xml"), good_, 100, spec));
    bytes_ = read_bytes(good_);
    records_ = top_level_records(bytes_);
  }
  // Applies `patch` to a copy of the good file (CRCs recomputed) and runs the doctor on it.
  mcap_tools::DoctorReport doctor_patched(const std::function<void(mcap::Bytes&)>& patch, bool fix = true) {
    mcap::Bytes b = bytes_;
    patch(b);
    if (fix) fix_crcs(b);
    write_bytes(dir_ / "patched.mcap", b);
    return mcap_tools::doctor((dir_ / "patched.mcap").string());
  }
  template <class T>
  void patch_record(mcap::Bytes& b, mcap::Opcode opcode, std::size_t nth,
                    const std::function<void(T&)>& change) {
    const RawRecord& at = find_record(records_, opcode, nth);
    T record = std::get<T>(parse_at(b, at));
    change(record);
    overwrite_record(b, at, record);
  }

  TempDir dir_;
  fs::path good_ = dir_ / "good.mcap";
  mcap::Bytes bytes_;
  std::vector<RawRecord> records_;
};

TEST_F(DoctorTest, GoodRecordingIsClean) {
  const auto r = mcap_tools::doctor(good_.string());
  EXPECT_TRUE(r.ok()) << dump(r);
  EXPECT_EQ(r.errors, 0u) << dump(r);
  EXPECT_EQ(r.warnings, 0u) << dump(r);
  ASSERT_GT(std::count_if(records_.begin(), records_.end(),
                          [](const RawRecord& x) {
                            return x.opcode == static_cast<std::uint8_t>(mcap::Opcode::Chunk);
                          }),
            3)
      << "the tests below want several chunks";
}

TEST_F(DoctorTest, PatchWithFixedCrcsIsStillClean) {
  // The helpers themselves: rewriting a record unchanged and recomputing the CRCs is a no-op.
  const auto r = doctor_patched([&](mcap::Bytes& b) {
    patch_record<mcap::Statistics>(b, mcap::Opcode::Statistics, 0, [](mcap::Statistics&) {});
  });
  EXPECT_EQ(r.errors, 0u) << dump(r);
}

TEST_F(DoctorTest, FlippedByteInAChunkIsACrcError) {
  const RawRecord& chunk = find_record(records_, mcap::Opcode::Chunk, 1);
  const std::uint64_t at = chunk.offset + chunk.length / 2;
  // Without fixing the CRCs: both the chunk and the data section are reported.
  const auto r = doctor_patched([&](mcap::Bytes& b) { b[at] ^= std::byte{0x10}; }, false);
  EXPECT_FALSE(r.ok());
  EXPECT_TRUE(has_finding(r, "Chunk at offset " + std::to_string(chunk.offset))) << dump(r);
  EXPECT_TRUE(has_finding(r, "data section CRC mismatch")) << dump(r);
}

TEST_F(DoctorTest, FlippedByteInAnUncompressedChunkIsAChunkCrcError) {
  RecordSpec spec;
  spec.chunk_size = 64 * 1024;
  spec.compression = mcap::Compression::None;
  const fs::path raw = dir_ / "raw.mcap";
  ASSERT_NO_FATAL_FAILURE(record_scene(source_path("scenes/cantilever.xml"), raw, 50, spec));
  mcap::Bytes b = read_bytes(raw);
  const RawRecord& chunk = find_record(top_level_records(b), mcap::Opcode::Chunk, 0);
  b[chunk.offset + chunk.length - 3] ^= std::byte{0x01};  // the last message's payload
  fix_crcs(b);                                            // only the chunk CRC can notice
  write_bytes(raw, b);
  const auto r = mcap_tools::doctor(raw.string());
  EXPECT_TRUE(has_finding(r, "invalid CRC")) << dump(r);
  EXPECT_FALSE(has_finding(r, "data section CRC")) << dump(r);
}

TEST_F(DoctorTest, WrongStatisticsAreErrors) {
  struct Case {
    const char* expect;
    std::function<void(mcap::Statistics&)> change;
  };
  const std::vector<Case> cases = {
      {"Statistics has message count", [](mcap::Statistics& s) { ++s.message_count; }},
      {"for channel 2", [](mcap::Statistics& s) { --s.channel_message_counts[2]; }},
      {"Statistics has channel count", [](mcap::Statistics& s) { ++s.channel_count; }},
      {"Statistics has schema count", [](mcap::Statistics& s) { --s.schema_count; }},
      {"Statistics has chunk count", [](mcap::Statistics& s) { ++s.chunk_count; }},
      {"Statistics has attachment count", [](mcap::Statistics& s) { ++s.attachment_count; }},
      {"Statistics has metadata count", [](mcap::Statistics& s) { ++s.metadata_count; }},
      {"Statistics has message start time", [](mcap::Statistics& s) { s.message_start_time += 1; }},
      {"Statistics has message end time", [](mcap::Statistics& s) { s.message_end_time -= 1; }},
  };
  for (const Case& c : cases) {
    const auto r = doctor_patched(
        [&](mcap::Bytes& b) { patch_record<mcap::Statistics>(b, mcap::Opcode::Statistics, 0, c.change); });
    EXPECT_EQ(r.errors, 1u) << c.expect << "\n" << dump(r);
    EXPECT_TRUE(has_finding(r, c.expect)) << dump(r);
  }
}

TEST_F(DoctorTest, StatisticsWithoutCrcFixAlsoBreakTheSummaryCrc) {
  const auto r = doctor_patched(
      [&](mcap::Bytes& b) {
        patch_record<mcap::Statistics>(b, mcap::Opcode::Statistics, 0,
                                       [](mcap::Statistics& s) { ++s.message_count; });
      },
      false);
  EXPECT_TRUE(has_finding(r, "summary CRC mismatch")) << dump(r);
  EXPECT_TRUE(has_finding(r, "Statistics has message count")) << dump(r);
}

TEST_F(DoctorTest, WrongChunkIndexFieldsAreErrors) {
  struct Case {
    const char* expect;
    std::function<void(mcap::ChunkIndex&)> change;
  };
  const std::vector<Case> cases = {
      {"has message start time", [](mcap::ChunkIndex& c) { c.message_start_time += 1; }},
      {"has message end time", [](mcap::ChunkIndex& c) { c.message_end_time += 1; }},
      {"length mismatch", [](mcap::ChunkIndex& c) { c.chunk_length += 1; }},
      {"compressed size", [](mcap::ChunkIndex& c) { c.compressed_size -= 1; }},
      {"uncompressed size", [](mcap::ChunkIndex& c) { c.uncompressed_size += 1; }},
      {"message_index_length", [](mcap::ChunkIndex& c) { c.message_index_length += 1; }},
      {"message index offset for channel",
       [](mcap::ChunkIndex& c) { c.message_index_offsets.begin()->second += 1; }},
      {"where there is no Chunk record", [](mcap::ChunkIndex& c) { c.chunk_start_offset += 1; }},
  };
  for (const Case& c : cases) {
    const auto r = doctor_patched(
        [&](mcap::Bytes& b) { patch_record<mcap::ChunkIndex>(b, mcap::Opcode::ChunkIndex, 1, c.change); });
    EXPECT_GE(r.errors, 1u) << c.expect;
    EXPECT_TRUE(has_finding(r, c.expect)) << c.expect << "\n" << dump(r);
  }
}

TEST_F(DoctorTest, MessageIndexEntriesMustPointAtMessagesWithTheirTimes) {
  auto r = doctor_patched([&](mcap::Bytes& b) {
    patch_record<mcap::MessageIndex>(b, mcap::Opcode::MessageIndex, 2,
                                     [](mcap::MessageIndex& m) { m.records.back().second += 1; });
  });
  EXPECT_TRUE(has_finding(r, "where there is no Message record")) << dump(r);
  EXPECT_TRUE(has_finding(r, "No MessageIndex entry found", false)) << dump(r);

  r = doctor_patched([&](mcap::Bytes& b) {
    patch_record<mcap::MessageIndex>(b, mcap::Opcode::MessageIndex, 2,
                                     [](mcap::MessageIndex& m) { m.records.front().first += 7; });
  });
  EXPECT_EQ(r.errors, 1u) << dump(r);
  EXPECT_TRUE(has_finding(r, "has timestamp")) << dump(r);

  // An entry naming another channel's message.
  r = doctor_patched([&](mcap::Bytes& b) {
    const auto first =
        std::get<mcap::MessageIndex>(parse_at(b, find_record(records_, mcap::Opcode::MessageIndex, 0)));
    patch_record<mcap::MessageIndex>(b, mcap::Opcode::MessageIndex, 1, [&](mcap::MessageIndex& m) {
      m.records.front().second = first.records.front().second;
    });
  });
  EXPECT_TRUE(has_finding(r, "points at a message of channel")) << dump(r);
}

TEST_F(DoctorTest, SummaryOffsetsMustPointAtTheirGroups) {
  auto r = doctor_patched([&](mcap::Bytes& b) {
    patch_record<mcap::SummaryOffset>(b, mcap::Opcode::SummaryOffset, 0,
                                      [](mcap::SummaryOffset& s) { s.group_start += 1; });
  });
  EXPECT_TRUE(has_finding(r, "is not the start of a summary record")) << dump(r);

  r = doctor_patched([&](mcap::Bytes& b) {
    patch_record<mcap::SummaryOffset>(b, mcap::Opcode::SummaryOffset, 0,
                                      [](mcap::SummaryOffset& s) { s.group_length -= 1; });
  });
  EXPECT_TRUE(has_finding(r, "record boundary")) << dump(r);

  r = doctor_patched([&](mcap::Bytes& b) {
    patch_record<mcap::SummaryOffset>(b, mcap::Opcode::SummaryOffset, 0, [](mcap::SummaryOffset& s) {
      s.group_opcode = static_cast<std::uint8_t>(mcap::Opcode::ChunkIndex);
    });
  });
  EXPECT_GE(r.errors, 1u) << dump(r);
}

TEST_F(DoctorTest, FooterOffsetsMustPointAtTheSummary) {
  auto r = doctor_patched([&](mcap::Bytes& b) {
    patch_record<mcap::Footer>(b, mcap::Opcode::Footer, 0, [](mcap::Footer& f) { f.summary_start += 9; });
  });
  EXPECT_TRUE(has_finding(r, "Footer.summary_start")) << dump(r);
  r = doctor_patched([&](mcap::Bytes& b) {
    patch_record<mcap::Footer>(b, mcap::Opcode::Footer, 0,
                               [](mcap::Footer& f) { f.summary_offset_start -= 1; });
  });
  EXPECT_TRUE(has_finding(r, "Footer.summary_offset_start")) << dump(r);
}

TEST_F(DoctorTest, DataSectionAndSummaryCrcs) {
  auto r = doctor_patched(
      [&](mcap::Bytes& b) {
        patch_record<mcap::DataEnd>(b, mcap::Opcode::DataEnd, 0,
                                    [](mcap::DataEnd& d) { d.data_section_crc ^= 1; });
      },
      false);
  EXPECT_EQ(r.errors, 1u) << dump(r);
  EXPECT_TRUE(has_finding(r, "data section CRC mismatch")) << dump(r);
  r = doctor_patched(
      [&](mcap::Bytes& b) {
        patch_record<mcap::Footer>(b, mcap::Opcode::Footer, 0, [](mcap::Footer& f) { f.summary_crc ^= 1; });
      },
      false);
  EXPECT_EQ(r.errors, 1u) << dump(r);
  EXPECT_TRUE(has_finding(r, "summary CRC mismatch")) << dump(r);
}

// A hand-made unchunked file: a channel naming an unknown schema, a message on an unknown channel.
TEST(DoctorCrafted, UnknownSchemaAndChannelReferences) {
  mcap::Bytes b(std::begin(mcap::kMagic), std::end(mcap::kMagic));
  mcap::serialize_record(mcap::Header{"", "test"}, b);
  mcap::serialize_record(mcap::Channel{1, 7, "/a", "json", {}}, b);
  mcap::serialize_record(mcap::Message{9, 0, 5, 5, bytes({1, 2, 3})}, b);
  mcap::serialize_record(mcap::Message{1, 1, 4, 4, bytes({1, 2, 3})}, b);  // earlier than the previous one
  mcap::serialize_record(mcap::DataEnd{0}, b);
  mcap::serialize_record(mcap::Footer{0, 0, 0}, b);
  b.insert(b.end(), std::begin(mcap::kMagic), std::end(mcap::kMagic));
  TempDir dir;
  write_bytes(dir / "x.mcap", b);
  const auto r = mcap_tools::doctor((dir / "x.mcap").string());
  EXPECT_TRUE(has_finding(r, "Encountered Channel (1) with unknown Schema (7)")) << dump(r);
  EXPECT_TRUE(has_finding(r, "Message record for channel: 9")) << dump(r);
  EXPECT_TRUE(has_finding(r, "less than the previous message record time")) << dump(r);
}

TEST(DoctorCrafted, OutOfOrderMessagesInChunksAreWarningsUnlessStrict) {
  mcap::Writer w;
  ASSERT_TRUE(w.open_buffer(recordings::writer_options(mcap::Compression::Zstd)).ok());
  const auto ch = w.add_channel(0, "/t", "raw");
  ASSERT_TRUE(ch.ok());
  for (std::uint32_t i = 0; i < 10; ++i)
    ASSERT_TRUE(w.write_message(ch.value(), i, 100 - i, 100 - i, mcap::Bytes{1}).ok());
  ASSERT_TRUE(w.close().ok());
  TempDir dir;
  write_bytes(dir / "x.mcap", w.buffer());
  auto r = mcap_tools::doctor((dir / "x.mcap").string());
  EXPECT_EQ(r.errors, 0u) << dump(r);
  EXPECT_TRUE(has_finding(r, "is less than the latest log time", false)) << dump(r);
  mcap_tools::DoctorOptions strict;
  strict.strict_message_order = true;
  r = mcap_tools::doctor((dir / "x.mcap").string(), strict);
  EXPECT_TRUE(has_finding(r, "is less than the latest log time", true)) << dump(r);
}

TEST_F(DoctorTest, TruncatedEmptyAndForeignFiles) {
  for (std::uint64_t cut : {std::uint64_t{0}, std::uint64_t{5}, std::uint64_t{8}, std::uint64_t{12},
                            bytes_.size() / 3, bytes_.size() - 40, bytes_.size() - 9, bytes_.size() - 1}) {
    mcap::Bytes b(bytes_.begin(), bytes_.begin() + static_cast<std::ptrdiff_t>(cut));
    write_bytes(dir_ / "cut.mcap", b);
    const auto r = mcap_tools::doctor((dir_ / "cut.mcap").string());
    EXPECT_FALSE(r.ok()) << "cut at " << cut;
    const std::string first = r.first_error();
    EXPECT_TRUE(first.find("truncated") != std::string::npos || first.find("empty file") != std::string::npos)
        << "cut at " << cut << ": " << first;
  }
  write_text(dir_ / "text.mcap", "name,value\n1,2\n");
  auto r = mcap_tools::doctor((dir_ / "text.mcap").string());
  EXPECT_EQ(r.first_error(), "not an MCAP file: the leading magic bytes are wrong");
  // The readers' callers word it the same (mcap::describe_read_error, through read_error).
  const Result<mcap_tools::LogInfo> info = mcap_tools::info((dir_ / "text.mcap").string());
  ASSERT_FALSE(info.ok());
  EXPECT_EQ(info.error().message, r.first_error());
  r = mcap_tools::doctor((dir_ / "missing.mcap").string());
  EXPECT_NE(r.first_error().find("cannot open"), std::string::npos) << r.first_error();
  r = mcap_tools::doctor(dir_.path().string());
  EXPECT_NE(r.first_error().find("directory"), std::string::npos) << r.first_error();
}

// Every single-byte flip and every truncation of a small file is an error: the data section and
// summary CRCs cover every byte. Also proves the doctor terminates on all of them.
TEST(DoctorHostile, EveryFlipAndEveryTruncationOfASmallFileIsAnError) {
  mcap::WriterOptions o = recordings::writer_options(mcap::Compression::Zstd, 200);
  mcap::Writer w;
  ASSERT_TRUE(w.open_buffer(o).ok());
  const auto schema = w.add_schema("S", "jsonschema", bytes_of("{}"));
  ASSERT_TRUE(schema.ok());
  const auto a = w.add_channel(schema.value(), "/a", "json", {{"k", "v"}});
  ASSERT_TRUE(a.ok());
  for (std::uint32_t i = 0; i < 12; ++i) {
    ASSERT_TRUE(w.write_message(a.value(), i, i, i, mcap::Bytes(20 + i, static_cast<std::byte>(i))).ok());
  }
  ASSERT_TRUE(w.add_attachment(1, 2, "x", "text/plain", bytes_of("hi")).ok());
  ASSERT_TRUE(w.add_metadata("m", {{"a", "b"}}).ok());
  ASSERT_TRUE(w.close().ok());
  const mcap::Bytes good = w.buffer();
  TempDir dir;
  const fs::path path = dir / "f.mcap";
  write_bytes(path, good);
  ASSERT_EQ(mcap_tools::doctor(path.string()).errors, 0u) << dump(mcap_tools::doctor(path.string()));
  for (std::size_t i = 0; i < good.size(); ++i) {
    mcap::Bytes b = good;
    b[i] ^= std::byte{0x04};
    write_bytes(path, b);
    EXPECT_FALSE(mcap_tools::doctor(path.string()).ok()) << "flip at byte " << i;
  }
  for (std::size_t n = 0; n < good.size(); ++n) {
    write_bytes(path, mcap::Bytes(good.begin(), good.begin() + static_cast<std::ptrdiff_t>(n)));
    EXPECT_FALSE(mcap_tools::doctor(path.string()).ok()) << "cut at " << n;
  }
}

// The 416 official conformance files: none of the checks beyond the Go doctor's reports a
// problem. The files are valid MCAP but not all ideal, so the Go doctor's own findings appear
// (out-of-order messages, indexed chunks whose channels the summary does not repeat, chunks
// without message indexes).
TEST(DoctorConformance, NoFalseErrorsOnTheOfficialFiles) {
  const std::regex go_parity(
      "Indexed chunk at offset [0-9]+ contains messages referencing (channel|schema) \\([0-9]+\\) not "
      "duplicated in "
      "summary section|Message.log_time [0-9]+ on \"[^\"]*\" is less than the previous message record "
      "time.*");
  std::size_t files = 0;
  for (const auto& entry : fs::recursive_directory_iterator(data_path("mcap-conformance"))) {
    if (entry.path().extension() != ".mcap") continue;
    ++files;
    const auto r = mcap_tools::doctor(entry.path().string());
    for (const auto& f : r.findings) {
      if (f.error) {
        EXPECT_TRUE(std::regex_match(f.text, go_parity)) << entry.path().filename() << ": " << f.text;
      }
    }
  }
  EXPECT_EQ(files, 416u);
}

}  // namespace
}  // namespace rbsim::test
