// mcap_tools::info at library level: from the summary, from a scan, and refusing damaged files.
#include <gtest/gtest.h>

#include "rbsim/subprocess.hpp"
#include "recordings_test_util.hpp"

namespace rbsim::test {
namespace {

namespace fs = std::filesystem;

TEST(Info, RecordingFromItsSummary) {
  TempDir dir;
  RecordSpec spec;
  spec.chunk_size = 64 * 1024;
  ASSERT_NO_FATAL_FAILURE(record_scene(source_path("scenes/cantilever.xml"), dir / "r.mcap", 100, spec));
  const auto info = mcap_tools::info((dir / "r.mcap").string());
  ASSERT_TRUE(info.ok()) << info.error().message;
  const mcap_tools::LogInfo& i = info.value();
  EXPECT_FALSE(i.scanned);
  EXPECT_EQ(i.header.profile, "ros2");
  EXPECT_EQ(i.header.library, "rbsim 0.1.0");
  EXPECT_EQ(i.messages, 2u + 6u * 101u);  // scene and markers once, six per-step topics for steps 0..100
  EXPECT_EQ(i.start, 0u);
  EXPECT_EQ(i.end, 100'000'000u);  // cantilever: dt = 0.001
  const auto chunks = chunk_message_counts(dir / "r.mcap");
  EXPECT_EQ(i.chunks, chunks.size());
  ASSERT_EQ(i.compression.size(), 1u);
  EXPECT_EQ(i.compression[0].compression, "zstd");
  EXPECT_EQ(i.compression[0].chunks, chunks.size());
  EXPECT_GT(i.compression[0].uncompressed_bytes, i.compression[0].compressed_bytes);
  ASSERT_EQ(i.channels.size(), 8u);
  EXPECT_EQ(i.channels[2].channel.topic, "/rbsim/body_states");
  EXPECT_EQ(i.channels[2].schema_name, "rbsim_msgs/msg/BodyStates");
  EXPECT_EQ(i.channels[2].schema_encoding, "ros2msg");
  EXPECT_EQ(i.channels[2].messages, 101u);
  EXPECT_EQ(i.channels[0].messages, 1u);
  EXPECT_EQ(i.channels[1].channel.topic, "/rbsim/markers");
  EXPECT_EQ(i.channels[1].messages, 1u);
  const std::string text = mcap_tools::format_info(i);
  for (const char* needle :
       {"library:     rbsim 0.1.0", "profile:     ros2", "messages:    608", "duration:    0.100000000 s",
        "start:       0.000000000 s", "end:         0.100000000 s", "zstd: [", "/rbsim/energy",
        "rbsim_msgs/msg/EnergyTerms [ros2msg]", "101 msgs (1010.00 Hz)", "attachments: 0", "metadata: 0"}) {
    EXPECT_NE(text.find(needle), std::string::npos) << needle << "\n" << text;
  }
}

TEST(Info, FileWithoutSummaryIsScanned) {
  mcap::WriterOptions o = recordings::writer_options(mcap::Compression::Lz4, 100);
  o.emit_statistics = o.emit_chunk_indexes = o.emit_summary_offsets = o.repeat_channels = o.repeat_schemas =
      false;
  o.emit_attachment_indexes = o.emit_metadata_indexes = false;
  mcap::Writer w;
  ASSERT_TRUE(w.open_buffer(o).ok());
  const auto s = w.add_schema("S", "jsonschema", bytes_of("{}"));
  ASSERT_TRUE(s.ok());
  const auto a = w.add_channel(s.value(), "/a", "json");
  const auto b = w.add_channel(0, "/b", "raw");
  ASSERT_TRUE(a.ok() && b.ok());
  for (std::uint32_t k = 0; k < 30; ++k) {
    ASSERT_TRUE(w.write_message(k % 3 ? a.value() : b.value(), k, 1'000'000'000ull + k, 0,
                                mcap::Bytes(40, std::byte{7}))
                    .ok());
  }
  ASSERT_TRUE(w.add_attachment(1, 2, "notes.txt", "text/plain", bytes_of("hi")).ok());
  ASSERT_TRUE(w.add_metadata("run", {{"k", "v"}}).ok());
  ASSERT_TRUE(w.close().ok());
  TempDir dir;
  write_bytes(dir / "x.mcap", w.buffer());
  const auto info = mcap_tools::info((dir / "x.mcap").string());
  ASSERT_TRUE(info.ok()) << info.error().message;
  const mcap_tools::LogInfo& i = info.value();
  EXPECT_TRUE(i.scanned);
  EXPECT_EQ(i.messages, 30u);
  EXPECT_EQ(i.start, 1'000'000'000u);
  EXPECT_EQ(i.end, 1'000'000'029u);
  ASSERT_EQ(i.channels.size(), 2u);
  EXPECT_EQ(i.channels[0].messages, 20u);
  EXPECT_EQ(i.channels[1].messages, 10u);
  EXPECT_EQ(i.channels[1].schema_name, "");
  ASSERT_EQ(i.compression.size(), 1u);
  EXPECT_EQ(i.compression[0].compression, "lz4");
  EXPECT_EQ(i.chunks, i.compression[0].chunks);
  EXPECT_GT(i.chunks, 3u);
  EXPECT_EQ(i.attachment_count, 1u);
  EXPECT_EQ(i.metadata_count, 1u);
  const std::string text = mcap_tools::format_info(i);
  EXPECT_NE(text.find("scan of the whole file"), std::string::npos) << text;
  EXPECT_NE(text.find("<no schema>"), std::string::npos) << text;
  EXPECT_NE(text.find("notes.txt"), std::string::npos) << text;
}

TEST(Info, DamagedFilesAreErrors) {
  TempDir dir;
  ASSERT_NO_FATAL_FAILURE(record_scene(source_path("scenes/cantilever.xml"), dir / "r.mcap", 50));
  const mcap::Bytes good = read_bytes(dir / "r.mcap");
  const fs::path bad = dir / "bad.mcap";
  auto expect_error = [&](const mcap::Bytes& b, const std::string& needle) {
    write_bytes(bad, b);
    const auto info = mcap_tools::info(bad.string());
    ASSERT_FALSE(info.ok());
    EXPECT_NE(info.error().message.find(needle), std::string::npos) << info.error().message;
  };
  expect_error({}, "empty file");
  expect_error(bytes({'P', 'K', 3, 4}), "not an MCAP file");
  expect_error(mcap::Bytes(good.begin(), good.end() - 100), "truncated");
  for (std::size_t at : {std::size_t{20}, good.size() / 2, good.size() - 200, good.size() - 20}) {
    mcap::Bytes b = good;
    b[at] ^= std::byte{0x01};
    write_bytes(bad, b);
    EXPECT_FALSE(mcap_tools::info(bad.string()).ok()) << "flip at " << at;
  }
}

}  // namespace
}  // namespace rbsim::test
