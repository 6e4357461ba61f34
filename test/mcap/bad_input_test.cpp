// Hostile input: truncation at every byte, flipped bytes, corrupt lengths, empty and non-MCAP
// files. Readers must fail with a clear status and never crash, hang or over-allocate.
#include <gtest/gtest.h>

#include "record_json.hpp"

namespace rbsim::mcap::test {
namespace {

Bytes small_file(Compression compression, bool chunks) {
  WriterOptions o;
  o.compression = compression;
  o.use_chunks = chunks;
  o.chunk_size = 200;
  Writer w;
  EXPECT_TRUE(w.open_buffer(o).ok());
  const std::uint16_t schema = w.add_schema("S", "jsonschema", bytes_of("{}")).value();
  const std::uint16_t a = w.add_channel(schema, "/a", "json", {{"k", "v"}}).value();
  const std::uint16_t b = w.add_channel(0, "/b", "raw").value();
  for (std::uint32_t i = 0; i < 12; ++i) {
    const Bytes data(20 + i, static_cast<std::byte>(i));
    EXPECT_TRUE(w.write_message(i % 2 ? a : b, i, 100 - i, 100 - i, data).ok());
  }
  EXPECT_TRUE(w.add_attachment(1, 2, "x", "text/plain", bytes_of("hi")).ok());
  EXPECT_TRUE(w.add_metadata("m", {{"a", "b"}}).ok());
  EXPECT_TRUE(w.close().ok());
  return w.buffer();
}

struct Outcome {
  bool ok = false;
  std::optional<ErrorCode> code;  // none: ok
  std::size_t records = 0;
};

Outcome stream_all(const Bytes& data, bool verify = true) {
  StreamReader r;
  StreamOptions o;
  o.verify_crcs = verify;
  o.report_chunks = o.report_message_indexes = true;
  EXPECT_TRUE(r.open_buffer(data, o).ok());
  Outcome out;
  RecordEntry e;
  // Each record consumes at least its 9-byte prefix, so this bound proves termination.
  while (r.next(e)) {
    ++out.records;
    if (out.records > data.size() + 1) {
      ADD_FAILURE() << "reader does not advance";
      break;
    }
  }
  out.ok = r.status().ok();
  out.code = r.status().code();
  if (!out.ok) {
    EXPECT_FALSE(r.status().error().message.empty());
  }
  return out;
}

Outcome index_all(const Bytes& data) {
  IndexedReader r;
  Outcome out;
  Status s = r.open_buffer(data);
  if (s.ok()) {
    auto m = r.read_all_messages();
    if (!m.ok()) s = m.error();
    if (m.ok()) out.records = m->size();
  }
  for (const auto& ai : r.attachment_indexes()) (void)r.read_attachment(ai).ok();
  for (const auto& mi : r.metadata_indexes()) (void)r.read_metadata(mi).ok();
  out.ok = s.ok();
  out.code = s.code();
  return out;
}

using Variant = std::pair<Compression, bool /*chunks*/>;
class CorruptFile : public ::testing::TestWithParam<Variant> {};

TEST_P(CorruptFile, TruncatedAtEveryByte) {
  const Bytes full = small_file(GetParam().first, GetParam().second);
  const Outcome whole = stream_all(full);
  ASSERT_TRUE(whole.ok);
  ASSERT_TRUE(index_all(full).ok);
  for (std::size_t n = 0; n < full.size(); ++n) {
    const Bytes cut(full.begin(), full.begin() + static_cast<std::ptrdiff_t>(n));
    const Outcome s = stream_all(cut);
    EXPECT_FALSE(s.ok) << "prefix " << n;
    EXPECT_LE(s.records, whole.records);
    if (n >= 8) {
      EXPECT_NE(s.code, ErrorCode::BadMagic) << "prefix " << n;
    }
    EXPECT_FALSE(index_all(cut).ok) << "prefix " << n;
  }
}

// With CRCs on, the streamed reader notices any flipped byte: before DataEnd through the data
// section CRC (or chunk CRC / structure), after it through the summary CRC or the magic.
TEST_P(CorruptFile, FlippedBytesAreDetected) {
  const Bytes full = small_file(GetParam().first, GetParam().second);
  for (std::size_t i = 0; i < full.size(); ++i) {
    for (std::uint8_t mask : {std::uint8_t{0xFF}, std::uint8_t{0x01}}) {
      Bytes bad = full;
      bad[i] ^= std::byte{mask};
      EXPECT_FALSE(stream_all(bad).ok) << "byte " << i << " mask " << int{mask};
      (void)stream_all(bad, false);
      (void)index_all(bad);
    }
  }
}

std::string variant_name(const ::testing::TestParamInfo<Variant>& info) {
  const char* names[] = {"None", "Lz4", "Zstd"};
  return std::string(names[static_cast<int>(info.param.first)]) +
         (info.param.second ? "_Chunked" : "_Unchunked");
}

INSTANTIATE_TEST_SUITE_P(All, CorruptFile,
                         ::testing::Values(Variant{Compression::Zstd, true}, Variant{Compression::Lz4, true},
                                           Variant{Compression::None, true},
                                           Variant{Compression::None, false}),
                         variant_name);

void set_u64(Bytes& b, std::size_t at, std::uint64_t v) {
  for (std::size_t i = 0; i < 8; ++i) b[at + i] = static_cast<std::byte>(v >> (8 * i));
}

TEST(BadInput, HugeLengthFieldsAreBoundedByTheFile) {
  Bytes file = small_file(Compression::Zstd, true);
  Bytes bad = file;
  set_u64(bad, 9, UINT64_MAX);  // Header length
  EXPECT_EQ(stream_all(bad).code, ErrorCode::Truncated);
  EXPECT_EQ(index_all(bad).code, ErrorCode::Truncated);

  // First chunk: find it, then claim an absurd uncompressed size.
  StreamReader r;
  StreamOptions o;
  o.descend_into_chunks = false;
  ASSERT_TRUE(r.open_buffer(file, o).ok());
  RecordEntry e;
  std::uint64_t chunk_at = 0;
  while (r.next(e)) {
    if (std::holds_alternative<Chunk>(e.record)) {
      chunk_at = e.offset;
      break;
    }
  }
  ASSERT_NE(chunk_at, 0u);
  bad = file;
  set_u64(bad, chunk_at + 9 + 16, UINT64_MAX / 2);  // Chunk.uncompressed_size
  EXPECT_FALSE(stream_all(bad, false).ok);
  EXPECT_FALSE(index_all(bad).ok);
  bad = file;
  set_u64(bad, chunk_at + 1, UINT64_MAX - 3);  // Chunk record length
  EXPECT_EQ(stream_all(bad, false).code, ErrorCode::Truncated);
}

TEST(BadInput, EmptyAndForeignFiles) {
  EXPECT_EQ(stream_all({}).code, ErrorCode::Truncated);
  EXPECT_EQ(index_all({}).code, ErrorCode::Truncated);
  const std::string text = "this is not an MCAP file, just some text that is long enough";
  const Bytes foreign = bytes_of(text);
  EXPECT_EQ(stream_all(foreign).code, ErrorCode::BadMagic);
  EXPECT_EQ(index_all(foreign).code, ErrorCode::BadMagic);
  const Bytes png = bytes({0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n', 0, 0, 0, 13});
  EXPECT_EQ(stream_all(png).code, ErrorCode::BadMagic);
  const Bytes magic_only(std::begin(kMagic), std::end(kMagic));
  EXPECT_EQ(stream_all(magic_only).code, ErrorCode::Truncated);
  EXPECT_EQ(stream_all(Bytes(kMagic, kMagic + 5)).code, ErrorCode::Truncated);

  StreamReader r;
  ASSERT_FALSE(r.open("/nonexistent/file.mcap").ok());
  RecordEntry e;
  EXPECT_FALSE(r.next(e));
  EXPECT_EQ(r.status().code(), ErrorCode::NotOpen);
  IndexedReader ir;
  EXPECT_EQ(ir.open("/nonexistent/file.mcap").code(), ErrorCode::IoError);
  EXPECT_EQ(ir.read_all_messages().code(), ErrorCode::NotOpen);
}

// Unknown opcodes and unknown trailing fields are skipped (spec: Records).
TEST(BadInput, UnknownRecordsAndFieldsAreSkipped) {
  Bytes file(std::begin(kMagic), std::end(kMagic));
  serialize_record(Header{"p", "l"}, file);
  serialize_record(UnknownRecord{0x80, bytes({9, 9})}, file);
  const std::size_t channel_at = file.size();
  serialize_record(Channel{1, 0, "/x", "raw", {}}, file);
  file.insert(file.end(), {std::byte{0xAA}, std::byte{0xBB}});  // two unknown trailing bytes on the Channel
  set_u64(file, channel_at + 1, file.size() - channel_at - 9);
  serialize_record(Message{1, 7, 5, 5, bytes({1})}, file);
  serialize_record(DataEnd{0}, file);
  serialize_record(Footer{}, file);
  file.insert(file.end(), std::begin(kMagic), std::end(kMagic));

  StreamReader r;
  ASSERT_TRUE(r.open_buffer(file).ok());
  std::vector<std::string> types;
  RecordEntry e;
  while (r.next(e)) types.emplace_back(record_type_name(e.record));
  ASSERT_TRUE(r.status().ok()) << r.status().error().message;
  EXPECT_EQ(types,
            (std::vector<std::string>{"Header", "Unknown", "Channel", "Message", "DataEnd", "Footer"}));
  IndexedReader ir;
  ASSERT_TRUE(ir.open_buffer(file).ok());
  EXPECT_EQ(ir.channels().at(1).topic, "/x");
  EXPECT_EQ(ir.read_all_messages()->size(), 1u);
}

}  // namespace
}  // namespace rbsim::mcap::test
