// Writer round trips through both readers, determinism, and crash-consistency of chunks.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <thread>
#include <tuple>

#include "record_json.hpp"

namespace rbsim::mcap::test {
namespace {

struct Sample {
  std::uint16_t channel = 0;
  std::uint32_t sequence = 0;
  Timestamp log_time = 0;
  Bytes data;
};

// Three topics, log times deliberately out of order with ties, payloads of varying size.
std::vector<Sample> samples() {
  std::vector<Sample> out;
  for (std::uint32_t i = 0; i < 300; ++i) {
    Sample s;
    s.channel = static_cast<std::uint16_t>(1 + i % 3);
    s.sequence = i;
    s.log_time = 1000 + (i * 7919) % 500;  // repeats: equal times must keep file order
    s.data.resize(1 + (i * 37) % 97);
    for (std::size_t k = 0; k < s.data.size(); ++k) s.data[k] = static_cast<std::byte>(i + k);
    out.push_back(std::move(s));
  }
  return out;
}

// Reads a file that was cut off (a killed writer): the messages a reader gets back, and its status.
std::size_t recovered_messages(const Bytes& partial, std::optional<ErrorCode>& ended) {
  StreamReader crashed;
  EXPECT_TRUE(crashed.open_buffer(partial).ok());
  std::size_t recovered = 0;
  RecordEntry e;
  while (crashed.next(e)) recovered += std::holds_alternative<Message>(e.record);
  ended = crashed.status().code();
  return recovered;
}

Bytes write_sample_file(const WriterOptions& options, const std::vector<Sample>& input) {
  Writer w;
  EXPECT_TRUE(w.open_buffer(options).ok());
  const Bytes schema_data = bytes_of("int");
  const std::uint16_t schema = w.add_schema("Pose", "ros2msg", schema_data).value();
  EXPECT_EQ(w.add_channel(schema, "/pose", "cdr", {{"qos", "reliable"}}).value(), 1);
  EXPECT_EQ(w.add_channel(schema, "/twist", "cdr").value(), 2);
  EXPECT_EQ(w.add_channel(0, "/log", "json").value(), 3);
  EXPECT_TRUE(w.add_metadata("robot", {{"name", "rb1"}, {"rev", "3"}}).ok());
  for (std::size_t i = 0; i < input.size(); ++i) {
    const Sample& s = input[i];
    EXPECT_TRUE(w.write_message(s.channel, s.sequence, s.log_time, s.log_time + 1, s.data).ok());
    if (i == input.size() / 2) {
      const Bytes blob = bytes({1, 2, 3, 4});
      EXPECT_TRUE(w.add_attachment(5, 6, "calib.bin", "application/octet-stream", blob).ok());
    }
  }
  EXPECT_TRUE(w.close().ok());
  return w.buffer();
}

using Params = std::tuple<Compression, bool /*chunks*/, bool /*indexes*/>;
class WriterRoundTrip : public ::testing::TestWithParam<Params> {
 protected:
  WriterOptions options() const {
    WriterOptions o;
    o.compression = std::get<0>(GetParam());
    o.use_chunks = std::get<1>(GetParam());
    const bool idx = std::get<2>(GetParam());
    o.emit_message_indexes = o.emit_chunk_indexes = o.emit_attachment_indexes = o.emit_metadata_indexes = idx;
    o.emit_statistics = o.emit_summary_offsets = o.repeat_schemas = o.repeat_channels = idx;
    o.chunk_size = 2048;  // several chunks
    return o;
  }
};

TEST_P(WriterRoundTrip, BothReadersReturnEveryMessage) {
  const auto input = samples();
  const Bytes file = write_sample_file(options(), input);
  EXPECT_EQ(file, write_sample_file(options(), input)) << "writer must be deterministic";

  // Streamed: file order, all CRCs verified.
  StreamReader stream;
  ASSERT_TRUE(stream.open_buffer(file).ok());
  std::vector<Message> streamed;
  int attachments = 0, metadata = 0;
  RecordEntry e;
  while (stream.next(e)) {
    if (auto* m = std::get_if<Message>(&e.record)) streamed.push_back(*m);
    attachments += std::holds_alternative<Attachment>(e.record);
    metadata += std::holds_alternative<Metadata>(e.record);
  }
  ASSERT_TRUE(stream.status().ok()) << stream.status().error().message;
  ASSERT_EQ(streamed.size(), input.size());
  for (std::size_t i = 0; i < input.size(); ++i) {
    EXPECT_EQ(streamed[i].channel_id, input[i].channel);
    EXPECT_EQ(streamed[i].sequence, input[i].sequence);
    EXPECT_EQ(streamed[i].log_time, input[i].log_time);
    EXPECT_EQ(streamed[i].publish_time, input[i].log_time + 1);
    EXPECT_EQ(streamed[i].data, input[i].data);
  }
  EXPECT_EQ(attachments, 1);
  EXPECT_EQ(metadata, 1);

  // Indexed: same messages, stably sorted by log time.
  IndexedReader indexed;
  ASSERT_TRUE(indexed.open_buffer(file).ok());
  EXPECT_EQ(indexed.indexed(), options().use_chunks && options().emit_chunk_indexes);
  EXPECT_TRUE(indexed.verify_data_section_crc().ok());
  auto all = indexed.read_all_messages();
  ASSERT_TRUE(all.ok()) << all.error().message;
  std::vector<Message> expected = streamed;
  std::stable_sort(expected.begin(), expected.end(),
                   [](const Message& a, const Message& b) { return a.log_time < b.log_time; });
  ASSERT_EQ(all->size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ((*all)[i].sequence, expected[i].sequence) << i;
    EXPECT_EQ((*all)[i].data, expected[i].data) << i;
  }
  ASSERT_EQ(indexed.channels().size(), 3u);
  EXPECT_EQ(indexed.channels().at(1).metadata.at("qos"), "reliable");
  EXPECT_EQ(indexed.schemas().at(1).name, "Pose");

  if (std::get<2>(GetParam())) {
    ASSERT_TRUE(indexed.statistics().has_value());
    const Statistics& st = *indexed.statistics();
    EXPECT_EQ(st.message_count, input.size());
    EXPECT_EQ(st.channel_count, 3u);
    EXPECT_EQ(st.schema_count, 1u);
    EXPECT_EQ(st.attachment_count, 1u);
    EXPECT_EQ(st.metadata_count, 1u);
    EXPECT_EQ(st.message_start_time, expected.front().log_time);
    EXPECT_EQ(st.message_end_time, expected.back().log_time);
    EXPECT_EQ(st.channel_message_counts.at(2), 100u);
    EXPECT_EQ(st.chunk_count, options().use_chunks ? indexed.chunk_indexes().size() : 0u);
    ASSERT_EQ(indexed.attachment_indexes().size(), 1u);
    auto att = indexed.read_attachment(indexed.attachment_indexes()[0]);
    ASSERT_TRUE(att.ok()) << att.error().message;
    EXPECT_EQ(att->data, bytes({1, 2, 3, 4}));
    EXPECT_NE(att->crc, 0u);
    ASSERT_EQ(indexed.metadata_indexes().size(), 1u);
    auto md = indexed.read_metadata(indexed.metadata_indexes()[0]);
    ASSERT_TRUE(md.ok());
    EXPECT_EQ(md->metadata.at("rev"), "3");
    EXPECT_FALSE(indexed.summary_offsets().empty());
  }
}

TEST_P(WriterRoundTrip, TopicAndTimeFilters) {
  const auto input = samples();
  IndexedReader indexed;
  ASSERT_TRUE(indexed.open_buffer(write_sample_file(options(), input)).ok());
  ReadMessagesOptions q;
  q.topics = {"/twist", "/log"};
  q.start_time = 1100;
  q.end_time = 1200;
  std::vector<std::uint32_t> got;
  ASSERT_TRUE(indexed
                  .read_messages(q,
                                 [&](const MessageEntry& e) {
                                   EXPECT_NE(e.channel, nullptr);
                                   EXPECT_EQ(e.schema == nullptr, e.message.channel_id == 3);
                                   got.push_back(e.message.sequence);
                                   return true;
                                 })
                  .ok());
  std::vector<const Sample*> want;
  for (const Sample& s : input) {
    if (s.channel != 1 && s.log_time >= 1100 && s.log_time < 1200) want.push_back(&s);
  }
  std::stable_sort(want.begin(), want.end(), [](auto* a, auto* b) { return a->log_time < b->log_time; });
  ASSERT_EQ(got.size(), want.size());
  for (std::size_t i = 0; i < want.size(); ++i) EXPECT_EQ(got[i], want[i]->sequence);

  std::size_t n = 0;  // returning false stops early
  ASSERT_TRUE(indexed.read_messages({}, [&](const MessageEntry&) { return ++n < 5; }).ok());
  EXPECT_EQ(n, 5u);
}

std::string param_name(const ::testing::TestParamInfo<Params>& info) {
  const char* c[] = {"None", "Lz4", "Zstd"};
  return std::string(c[static_cast<int>(std::get<0>(info.param))]) +
         (std::get<1>(info.param) ? "_Chunked" : "_Unchunked") +
         (std::get<2>(info.param) ? "_Indexed" : "_NoIndex");
}

INSTANTIATE_TEST_SUITE_P(All, WriterRoundTrip,
                         ::testing::Combine(::testing::Values(Compression::None, Compression::Lz4,
                                                              Compression::Zstd),
                                            ::testing::Bool(), ::testing::Bool()),
                         param_name);

class WriterFile : public ::testing::TestWithParam<bool /*background_compression*/> {};

TEST_P(WriterFile, FileOutputMatchesBufferAndFlushesChunks) {
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("rbsim_mcap_writer_test" + std::to_string(GetParam()) + ".mcap"))
                               .string();
  WriterOptions o;
  o.chunk_size = 1024;
  o.background_compression = GetParam();
  const auto input = samples();
  Writer w;
  ASSERT_TRUE(w.open(path, o).ok());
  const std::uint16_t ch = w.add_channel(0, "/t", "raw").value();
  for (const Sample& s : input)
    ASSERT_TRUE(w.write_message(ch, s.sequence, s.log_time, s.log_time, s.data).ok());

  // Before close: the file holds every completed chunk, as after a killed process.
  std::optional<ErrorCode> ended;
  const std::size_t recovered = recovered_messages(read_file(path), ended);
  EXPECT_EQ(ended, ErrorCode::Truncated);
  EXPECT_GT(recovered, input.size() / 2);
  EXPECT_LT(recovered, input.size());

  ASSERT_TRUE(w.close().ok());
  Writer mem;
  ASSERT_TRUE(mem.open_buffer(o).ok());
  ASSERT_EQ(mem.add_channel(0, "/t", "raw").value(), ch);
  for (const Sample& s : input)
    ASSERT_TRUE(mem.write_message(ch, s.sequence, s.log_time, s.log_time, s.data).ok());
  ASSERT_TRUE(mem.close().ok());
  EXPECT_EQ(read_file(path), mem.buffer());
  std::remove(path.c_str());
}

INSTANTIATE_TEST_SUITE_P(All, WriterFile, ::testing::Bool(), [](const ::testing::TestParamInfo<bool>& i) {
  return i.param ? "Background" : "Inline";
});

TEST(Writer, RejectsBadUse) {
  Writer w;
  EXPECT_EQ(w.write_message(1, 0, 0, 0, {}).code(), ErrorCode::NotOpen);
  EXPECT_EQ(w.close().code(), ErrorCode::NotOpen);
  ASSERT_TRUE(w.open_buffer().ok());
  EXPECT_EQ(w.open_buffer().code(), ErrorCode::InvalidArgument);
  EXPECT_EQ(w.add_channel(7, "/t", "raw").code(), ErrorCode::InvalidArgument);
  EXPECT_EQ(w.write_message(1, 0, 0, 0, {}).code(), ErrorCode::InvalidArgument);
  ASSERT_TRUE(w.close().ok());
  EXPECT_EQ(w.open("/nonexistent-dir/x.mcap").code(), ErrorCode::IoError);
}

// Copying records with their own ids (what a recover tool does) keeps the ids.
TEST(Writer, KeepsExplicitIds) {
  Writer w;
  ASSERT_TRUE(w.open_buffer().ok());
  const Schema schema{7, "S", "jsonschema", bytes_of("{}")};
  const Channel channel{42, 7, "/x", "json", {{"a", "b"}}};
  ASSERT_TRUE(w.add_schema(schema).ok());
  ASSERT_TRUE(w.add_schema(schema).ok());  // identical: no-op
  EXPECT_EQ(w.add_schema(Schema{7, "T", "", {}}).code(), ErrorCode::InvalidArgument);
  EXPECT_EQ(w.add_schema(Schema{0, "S", "", {}}).code(), ErrorCode::InvalidArgument);
  ASSERT_TRUE(w.add_channel(channel).ok());
  EXPECT_EQ(w.add_channel(Channel{43, 9, "/y", "json", {}}).code(), ErrorCode::InvalidArgument);
  EXPECT_EQ(w.add_channel(0, "/next", "raw").value(), 43);
  ASSERT_TRUE(w.write_message(Message{42, 1, 10, 11, bytes({5})}).ok());
  ASSERT_TRUE(w.close().ok());
  IndexedReader r;
  ASSERT_TRUE(r.open_buffer(w.buffer()).ok());
  EXPECT_EQ(r.schemas().at(7).name, "S");
  EXPECT_EQ(r.channels().at(42).topic, "/x");
  auto messages = r.read_all_messages();
  ASSERT_TRUE(messages.ok());
  ASSERT_EQ(messages->size(), 1u);
  EXPECT_EQ((*messages)[0].channel_id, 42);
  EXPECT_EQ((*messages)[0].publish_time, 11u);
}

// A chunk copied as stored (IndexedReader::read_chunk, read_message_indexes -> Writer::copy_chunk)
// between messages written anew: every message read back in order, indexes and statistics right.
TEST(Writer, CopyChunkKeepsAChunkAsStored) {
  WriterOptions o;
  o.chunk_size = 200;
  Writer src;
  ASSERT_TRUE(src.open_buffer(o).ok());
  ASSERT_TRUE(src.add_schema(Schema{1, "S", "jsonschema", bytes_of("{}")}).ok());
  ASSERT_TRUE(src.add_channel(Channel{1, 1, "/a", "json", {}}).ok());
  ASSERT_TRUE(src.add_channel(Channel{2, 1, "/b", "json", {}}).ok());
  for (std::uint32_t i = 0; i < 60; ++i)
    ASSERT_TRUE(
        src.write_message(static_cast<std::uint16_t>(1 + i % 2), i, 10 * i, 10 * i, bytes({1, 2, 3, 4}))
            .ok());
  ASSERT_TRUE(src.close().ok());
  IndexedReader in;
  ASSERT_TRUE(in.open_buffer(src.buffer()).ok());
  ASSERT_GE(in.chunk_indexes().size(), 3u);
  const ChunkIndex& middle = in.chunk_indexes()[1];
  auto chunk = in.read_chunk(middle);
  ASSERT_TRUE(chunk.ok()) << chunk.error().message;
  auto indexes = in.read_message_indexes(middle);
  ASSERT_TRUE(indexes.ok()) << indexes.error().message;
  std::uint64_t copied = 0;
  for (const MessageIndex& mi : *indexes) copied += mi.records.size();
  ASSERT_GT(copied, 0u);

  for (Compression c : {Compression::Zstd, Compression::None}) {
    o.compression = c;
    Writer out;
    ASSERT_TRUE(out.open_buffer(o).ok());
    ASSERT_TRUE(out.add_schema(in.schemas().at(1)).ok());
    ASSERT_TRUE(out.add_channel(in.channels().at(1)).ok());
    if (c == Compression::None) {  // another codec, and a channel the writer lacks, are refused
      EXPECT_EQ(out.copy_chunk(*chunk, *indexes).code(), ErrorCode::InvalidArgument);
      continue;
    }
    EXPECT_EQ(out.copy_chunk(*chunk, *indexes).code(), ErrorCode::InvalidArgument);  // no /b yet
    ASSERT_TRUE(out.add_channel(in.channels().at(2)).ok());
    ASSERT_TRUE(out.write_message(1, 100, 1, 1, bytes({9})).ok());  // before the copy: its own chunk
    ASSERT_TRUE(out.copy_chunk(*chunk, *indexes).ok());
    ASSERT_TRUE(out.write_message(2, 101, 5000, 5000, bytes({8})).ok());
    ASSERT_TRUE(out.close().ok());
    IndexedReader back;
    ASSERT_TRUE(back.open_buffer(out.buffer()).ok());
    auto all = back.read_all_messages();
    ASSERT_TRUE(all.ok()) << all.error().message;
    ASSERT_EQ(all->size(), copied + 2);
    EXPECT_EQ(all->front().sequence, 100u);
    EXPECT_EQ(all->back().sequence, 101u);
    for (std::size_t i = 1; i + 1 < all->size(); ++i) {
      EXPECT_GE((*all)[i].log_time, middle.message_start_time);
      EXPECT_LE((*all)[i].log_time, middle.message_end_time);
      EXPECT_EQ((*all)[i].data, bytes({1, 2, 3, 4}));
    }
    ASSERT_TRUE(back.statistics().has_value());
    EXPECT_EQ(back.statistics()->message_count, copied + 2);
    EXPECT_EQ(back.statistics()->chunk_count, 3u);
    EXPECT_EQ(back.chunk_indexes().size(), 3u);
    EXPECT_EQ(back.chunk_indexes()[1].compressed_size, middle.compressed_size);
    EXPECT_TRUE(back.verify_data_section_crc().ok());
  }
}

TEST(Writer, EmptyFileIsValid) {
  Writer w;
  ASSERT_TRUE(w.open_buffer().ok());
  ASSERT_TRUE(w.close().ok());
  IndexedReader r;
  ASSERT_TRUE(r.open_buffer(w.buffer()).ok());
  EXPECT_EQ(r.header().library, "rbsim-mcap");
  ASSERT_TRUE(r.statistics().has_value());
  EXPECT_EQ(r.statistics()->message_count, 0u);
}

// The worker thread changes when chunks are compressed, never the bytes: every codec, chunk sizes
// from one message per chunk up, with and without CRCs, attachments and metadata between chunks.
TEST(Writer, BackgroundCompressionWritesTheSameBytes) {
  const auto input = samples();
  for (Compression c : {Compression::None, Compression::Lz4, Compression::Zstd}) {
    for (std::uint64_t chunk_size : {1u, 700u, 2048u, 1u << 20}) {
      for (bool crcs : {true, false}) {
        WriterOptions o;
        o.compression = c;
        o.chunk_size = chunk_size;
        o.enable_crcs = crcs;
        const Bytes inline_file = write_sample_file(o, input);
        o.background_compression = true;
        EXPECT_EQ(write_sample_file(o, input), inline_file)
            << to_string(c) << " chunk_size " << chunk_size << " crcs " << crcs;
      }
    }
  }
}

// A chunk compressed while the writer sits idle reaches the file through write_compressed_chunk,
// without another message (what `rbsim record` calls while it waits for samples).
TEST(Writer, WriteCompressedChunkWritesAFinishedChunkWhileIdle) {
  const std::string path = (std::filesystem::temp_directory_path() / "rbsim_mcap_idle_chunk.mcap").string();
  WriterOptions o;
  o.chunk_size = 1024;
  o.background_compression = true;
  Writer w;
  ASSERT_TRUE(w.open(path, o).ok());
  const std::uint16_t ch = w.add_channel(0, "/t", "raw").value();
  const Bytes big(2000, std::byte{7});  // one message fills a chunk: it is handed to the worker at once
  ASSERT_TRUE(w.write_message(ch, 0, 10, 10, big).ok());
  EXPECT_EQ(w.statistics().chunk_count, 0u) << "written before it could have been compressed";
  for (int i = 0; i < 5000 && w.statistics().chunk_count == 0; ++i) {
    ASSERT_TRUE(w.write_compressed_chunk().ok());
    if (w.statistics().chunk_count == 0) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  ASSERT_EQ(w.statistics().chunk_count, 1u);
  std::optional<ErrorCode> ended;  // as after a killed process
  EXPECT_EQ(recovered_messages(read_file(path), ended), 1u);
  ASSERT_TRUE(w.close().ok());
  std::remove(path.c_str());
}

// A full disk surfaces as an error from the writer's calls (not a crash or a hang), with or
// without the worker.
TEST(Writer, ReportsWriteErrorsWithBackgroundCompression) {
  if (!std::filesystem::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  for (bool background : {false, true}) {
    WriterOptions o;
    o.chunk_size = 256;
    o.background_compression = background;
    Writer w;
    ASSERT_TRUE(w.open("/dev/full", o).ok());
    const std::uint16_t ch = w.add_channel(0, "/t", "raw").value();
    Status first;
    for (const Sample& s : samples()) {
      first = w.write_message(ch, s.sequence, s.log_time, s.log_time, s.data);
      if (!first.ok()) break;
    }
    const Status closed = w.close();
    EXPECT_FALSE(first.ok() && closed.ok()) << "background " << background;
    EXPECT_EQ((first.ok() ? closed : first).code(), ErrorCode::IoError) << "background " << background;
  }
}

TEST(Crc32, MatchesZlib) {
  const Bytes s = bytes_of("123456789");
  const ByteView v(s);
  EXPECT_EQ(crc32(v), 0xCBF43926u);
  EXPECT_EQ(crc32(v.subspan(4), crc32(v.first(4))), 0xCBF43926u);
  EXPECT_EQ(crc32({}), 0u);
  EXPECT_EQ(crc32({}, 0x1234u), 0x1234u);
}

// Long inputs take the library's vectorised path: it must agree with the definition (one bit at a
// time, reflected polynomial 0xEDB88320) at every length and split around its block sizes.
TEST(Crc32, LongInputsMatchTheBitwiseDefinition) {
  Bytes data(70'000);
  std::uint32_t x = 12345;
  for (auto& b : data) b = static_cast<std::byte>((x = x * 1103515245u + 12345u) >> 24);
  const auto bitwise = [](ByteView v) {
    std::uint32_t c = 0xFFFFFFFFu;
    for (std::byte b : v) {
      c ^= std::to_integer<std::uint32_t>(b);
      for (int k = 0; k < 8; ++k) c = (c & 1u) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
    }
    return ~c;
  };
  const ByteView all(data);
  for (std::size_t n : {1u, 15u, 16u, 63u, 64u, 65u, 255u, 256u, 4097u, 70'000u}) {
    EXPECT_EQ(crc32(all.first(n)), bitwise(all.first(n))) << n;
  }
  const std::uint32_t whole = bitwise(all);
  for (std::size_t split : {1u, 7u, 64u, 1000u, 65'537u}) {
    EXPECT_EQ(crc32(all.subspan(split), crc32(all.first(split))), whole) << split;
  }
}

TEST(Crc32, CombineEqualsTheCrcOfTheConcatenation) {
  Bytes data(70'000);
  std::uint32_t x = 777;
  for (auto& b : data) b = static_cast<std::byte>((x = x * 1103515245u + 12345u) >> 24);
  const ByteView all(data);
  for (std::size_t split : {0u, 1u, 3u, 64u, 4096u, 69'999u, 70'000u}) {
    for (std::size_t end : {split, split + (70'000u - split) / 3, std::size_t{70'000u}}) {
      const ByteView a = all.first(split), b = all.subspan(split, end - split);
      EXPECT_EQ(crc32_combine(crc32(a), crc32(b), b.size()), crc32(all.first(end))) << split << " " << end;
    }
  }
}

// The records of `count` samples, all on channel 1, written to `path` or to memory.
Bytes write_uncompressed(const std::string& path, std::uint64_t chunk_size, bool crcs) {
  WriterOptions o;
  o.compression = Compression::None;
  o.chunk_size = chunk_size;
  o.enable_crcs = crcs;
  Writer w;
  EXPECT_TRUE((path.empty() ? w.open_buffer(o) : w.open(path, o)).ok());
  const Bytes schema_data = bytes_of("int");
  const std::uint16_t schema = w.add_schema("Pose", "ros2msg", schema_data).value();
  EXPECT_EQ(w.add_channel(schema, "/pose", "cdr").value(), 1);
  EXPECT_EQ(w.add_channel(0, "/log", "json").value(), 2);
  for (const Sample& s : samples()) {
    EXPECT_TRUE(w.write_message(s.channel % 2 + 1, s.sequence, s.log_time, s.log_time, s.data).ok());
  }
  EXPECT_TRUE(w.close().ok());
  return w.buffer();
}

// Uncompressed chunks are streamed to a file that can seek (and to memory), and built in memory
// for one that cannot (a pipe): the same bytes either way, CRCs included.
TEST(Writer, StreamedUncompressedChunksMatchBufferedOnes) {
  const auto dir = std::filesystem::temp_directory_path();
  const std::string fifo = (dir / ("rbsim_mcap_fifo_" + std::to_string(::getpid()))).string();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  for (std::uint64_t chunk_size : {1u, 700u, 1u << 20}) {
    for (bool crcs : {true, false}) {
      const Bytes streamed = write_uncompressed("", chunk_size, crcs);
      Bytes piped;
      std::thread reader([&] {
        std::FILE* f = std::fopen(fifo.c_str(), "rb");
        ASSERT_NE(f, nullptr);
        std::byte buf[4096];
        for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, f)) > 0;)
          piped.insert(piped.end(), buf, buf + n);
        std::fclose(f);
      });
      write_uncompressed(fifo, chunk_size, crcs);
      reader.join();
      const auto diff = std::mismatch(streamed.begin(), streamed.end(), piped.begin(), piped.end());
      EXPECT_TRUE(streamed == piped) << "chunk_size " << chunk_size << " crcs " << crcs << ": sizes "
                                     << streamed.size() << " and " << piped.size() << ", first difference at "
                                     << (diff.first - streamed.begin());
      StreamReader r;  // every CRC checked
      ASSERT_TRUE(r.open_buffer(streamed).ok());
      RecordEntry e;
      std::size_t messages = 0;
      while (r.next(e)) messages += std::holds_alternative<Message>(e.record);
      EXPECT_TRUE(r.status().ok()) << r.status().error().message;
      EXPECT_EQ(messages, samples().size());
    }
  }
  std::remove(fifo.c_str());
}

// While a streamed chunk is open the file ends in a Chunk record that claims more bytes than it
// has: readers see the complete chunks before it and stop there, as after a cut-off write.
TEST(Writer, OpenStreamedChunkReadsAsTruncated) {
  const std::string path = (std::filesystem::temp_directory_path() / "rbsim_mcap_streamed.mcap").string();
  WriterOptions o;
  o.compression = Compression::None;
  o.chunk_size = 1024;
  Writer w;
  ASSERT_TRUE(w.open(path, o).ok());
  const std::uint16_t ch = w.add_channel(0, "/t", "raw").value();
  const auto input = samples();
  for (const Sample& s : input)
    ASSERT_TRUE(w.write_message(ch, s.sequence, s.log_time, s.log_time, s.data).ok());
  ASSERT_TRUE(w.flush_chunk().ok());
  ASSERT_TRUE(w.write_message(ch, 0, 1, 1, input[0].data).ok());  // opens the next chunk
  std::optional<ErrorCode> ended;
  const std::size_t recovered = recovered_messages(read_file(path), ended);
  EXPECT_EQ(ended, ErrorCode::Truncated);
  EXPECT_EQ(recovered, input.size());
  ASSERT_TRUE(w.close().ok());
  EXPECT_EQ(recovered_messages(read_file(path), ended), input.size() + 1);
  EXPECT_FALSE(ended.has_value());  // read to its end
  std::remove(path.c_str());
}

}  // namespace
}  // namespace rbsim::mcap::test
