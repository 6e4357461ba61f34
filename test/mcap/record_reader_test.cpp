// The public record framing (rbsim/mcap_records.hpp): RecordReader over file, buffer and view
// sources, its problems on truncated and corrupt lengths, the magic and Footer helpers.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>

#include "rbsim/mcap_records.hpp"
#include "record_json.hpp"

namespace rbsim::mcap::test {
namespace {

// A chunked file with message indexes, an attachment and a summary: every kind of top-level record.
Bytes recording() {
  WriterOptions o;
  o.compression = Compression::None;
  o.chunk_size = 300;
  Writer w;
  EXPECT_TRUE(w.open_buffer(o).ok());
  const std::uint16_t schema = w.add_schema("S", "jsonschema", bytes_of("{}")).value();
  const std::uint16_t channel = w.add_channel(schema, "/a", "json").value();
  for (std::uint32_t i = 0; i < 20; ++i) {
    EXPECT_TRUE(w.write_message(channel, i, 10 * i, 10 * i, Bytes(40, static_cast<std::byte>(i))).ok());
  }
  EXPECT_TRUE(w.add_attachment(1, 2, "x", "text/plain", bytes_of("hi")).ok());
  EXPECT_TRUE(w.close().ok());
  return w.buffer();
}

// Every record of [begin, end) of `source`, in order; fails the test on a problem.
std::vector<RecordView> all_records(ByteSource& source, std::uint64_t begin, std::uint64_t end,
                                    std::vector<Bytes>* contents = nullptr) {
  RecordReader reader(source, begin, end);
  std::vector<RecordView> out;
  for (RecordView r; reader.next(r);) {
    out.push_back(r);
    if (contents != nullptr) contents->emplace_back(r.content.begin(), r.content.end());
    out.back().content = {};  // views the source only until its next read
    if (out.size() > source.size()) break;
  }
  EXPECT_TRUE(reader.status().ok()) << reader.status().error().message;
  EXPECT_TRUE(reader.at_end());
  return out;
}

std::uint64_t length_field(const RecordView& r) {
  std::uint64_t v = 0;
  for (int i = 8; i >= 1; --i) v = (v << 8) | std::to_integer<std::uint64_t>(r.prefix[i]);
  return v;
}

TEST(RecordReader, ReadsAGoodFileRecordByRecord) {
  const Bytes file = recording();
  auto source = make_buffer_source(file);
  ASSERT_TRUE(check_magic(*source, 0).ok());
  const auto records = all_records(*source, kMagicSize, file.size() - kMagicSize);
  ASSERT_GE(records.size(), 6u);

  // The same records, at the same offsets, as the stream reader frames them.
  StreamReader stream;
  StreamOptions so;
  so.descend_into_chunks = false;
  so.report_message_indexes = true;
  ASSERT_TRUE(stream.open_buffer(file, so).ok());
  std::size_t i = 0;
  for (RecordEntry e; stream.next(e); ++i) {
    ASSERT_LT(i, records.size());
    EXPECT_EQ(records[i].opcode, opcode_of(e.record)) << i;
    EXPECT_EQ(records[i].offset, e.offset) << i;
    EXPECT_EQ(records[i].length, e.length) << i;
  }
  ASSERT_TRUE(stream.status().ok()) << stream.status().error().message;
  EXPECT_EQ(i, records.size());

  std::uint64_t at = kMagicSize;
  for (const RecordView& r : records) {
    EXPECT_EQ(r.offset, at);
    EXPECT_EQ(std::to_integer<std::uint8_t>(r.prefix[0]), r.opcode);
    EXPECT_EQ(length_field(r) + RecordReader::kPrefixSize, r.length);
    EXPECT_TRUE(is_known_opcode(r.opcode)) << opcode_name(r.opcode);
    at += r.length;
  }
  EXPECT_EQ(records.front().opcode, opcode_of<Header>());
  EXPECT_EQ(records.back().opcode, opcode_of<Footer>());
  EXPECT_EQ(records.back().offset, footer_offset(file.size()));
  EXPECT_TRUE(check_magic(*source, at).ok());

  RecordView header;
  ASSERT_TRUE(read_record(*source, kMagicSize, header).ok());
  EXPECT_EQ(header.opcode, opcode_of<Header>());
  auto footer = read_footer(*source);
  ASSERT_TRUE(footer.ok()) << footer.error().message;
  EXPECT_NE(footer.value().summary_start, 0u);
}

TEST(RecordReader, ReportsATruncatedRecordWithItsOffset) {
  const Bytes file = recording();
  auto whole = make_buffer_source(file);
  const auto records = all_records(*whole, kMagicSize, file.size() - kMagicSize);
  const RecordView& cut = records[2];
  // Inside the prefix (3 bytes of it left), then inside the content (its prefix whole).
  for (const std::uint64_t keep : {std::uint64_t{3}, cut.length - 1}) {
    SCOPED_TRACE(keep);
    const Bytes truncated(file.begin(), file.begin() + static_cast<std::ptrdiff_t>(cut.offset + keep));
    auto source = make_buffer_source(truncated);
    RecordReader reader(*source, kMagicSize);
    std::vector<RecordProblem> problems;
    reader.on_problem([&](const RecordProblem& p) { problems.push_back(p); });
    std::size_t read = 0;
    for (RecordView r; reader.next(r);) ++read;
    EXPECT_EQ(read, 2u);
    RecordView after;
    EXPECT_FALSE(reader.next(after));  // stays stopped, reports once
    ASSERT_EQ(problems.size(), 1u);
    const RecordProblem& p = problems.front();
    EXPECT_EQ(p.offset, cut.offset);
    EXPECT_EQ(p.available, keep);
    EXPECT_EQ(p.status.code(), ErrorCode::Truncated);
    EXPECT_NE(p.status.error().message.find("at offset " + std::to_string(cut.offset)), std::string::npos)
        << p.status.error().message;
    ASSERT_TRUE(p.opcode.has_value());
    EXPECT_EQ(*p.opcode, cut.opcode);
    EXPECT_EQ(p.content_length.has_value(), keep >= RecordReader::kPrefixSize);
    if (p.content_length) {
      EXPECT_EQ(*p.content_length, cut.length - RecordReader::kPrefixSize);
    }
    EXPECT_EQ(reader.position(), cut.offset);
    EXPECT_EQ(reader.problem().offset, cut.offset);
    EXPECT_EQ(reader.status().code(), ErrorCode::Truncated);
  }
}

TEST(RecordReader, ALengthPastTheEndIsAProblemNotARead) {
  Bytes file = recording();
  auto good = make_buffer_source(file);
  const auto records = all_records(*good, kMagicSize, file.size() - kMagicSize);
  const RecordView& bad = records[1];
  for (std::size_t i = 1; i <= 8; ++i) file[bad.offset + i] = std::byte{0xFF};  // length UINT64_MAX
  auto source = make_buffer_source(file);
  RecordReader reader(*source, kMagicSize);
  RecordView r;
  ASSERT_TRUE(reader.next(r));
  EXPECT_FALSE(reader.next(r));
  const RecordProblem& p = reader.problem();
  EXPECT_EQ(p.status.code(), ErrorCode::Truncated);
  EXPECT_EQ(p.offset, bad.offset);
  EXPECT_EQ(p.content_length, UINT64_MAX);
  EXPECT_EQ(p.available, file.size() - bad.offset);
  EXPECT_NE(p.status.error().message.find("claims 18446744073709551615 bytes"), std::string::npos)
      << p.status.error().message;

  // A caller may resync past the bad record and read on.
  reader.seek(records[2].offset);
  EXPECT_TRUE(reader.status().ok());
  ASSERT_TRUE(reader.next(r));
  EXPECT_EQ(r.offset, records[2].offset);
  EXPECT_EQ(r.opcode, records[2].opcode);

  RecordView one;
  EXPECT_EQ(read_record(*source, bad.offset, one).code(), ErrorCode::Truncated);
  EXPECT_EQ(read_record(*source, file.size(), one).code(), ErrorCode::Truncated);
}

TEST(CheckMagic, BadTruncatedAndGoodMagic) {
  const Bytes file = recording();
  auto good = make_buffer_source(file);
  EXPECT_TRUE(check_magic(*good, 0).ok());
  EXPECT_TRUE(check_magic(*good, file.size() - kMagicSize).ok());
  EXPECT_EQ(check_magic(*good, kMagicSize).code(), ErrorCode::BadMagic);  // the Header, not magic

  Bytes flipped = file;
  flipped[3] ^= std::byte{0x20};  // 'C' -> 'c'
  auto bad = make_buffer_source(flipped);
  const Status s = check_magic(*bad, 0);
  EXPECT_EQ(s.code(), ErrorCode::BadMagic);
  EXPECT_EQ(s.error().message, "the leading magic bytes are wrong");

  auto short_good = make_buffer_source(Bytes(file.begin(), file.begin() + 5));
  EXPECT_EQ(check_magic(*short_good, 0).code(), ErrorCode::Truncated);
  EXPECT_EQ(check_magic(*short_good, 0).error().message, "the file ends inside the leading magic (5 bytes)");
  auto short_bad = make_buffer_source(Bytes(flipped.begin(), flipped.begin() + 5));
  EXPECT_EQ(check_magic(*short_bad, 0).code(), ErrorCode::BadMagic);

  // Without its trailing magic a file has no Footer to read.
  auto cut = make_buffer_source(Bytes(file.begin(), file.end() - 1));
  EXPECT_EQ(read_footer(*cut).code(), ErrorCode::Truncated);
}

// The one wording of a read error: what the file is by the code, then the reader's message.
TEST(DescribeReadError, SaysWhatTheFileIsByTheCode) {
  EXPECT_EQ(describe_read_error({"the leading magic bytes are wrong", ErrorCode::BadMagic}),
            "not an MCAP file: the leading magic bytes are wrong");
  EXPECT_EQ(describe_read_error({"no trailing magic", ErrorCode::Truncated}), "truncated: no trailing magic");
  for (ErrorCode c : {ErrorCode::CrcMismatch, ErrorCode::DecompressionFailed, ErrorCode::Malformed})
    EXPECT_EQ(describe_read_error({"chunk at 9", c}), "corrupted: chunk at 9");
  EXPECT_EQ(describe_read_error({"cannot read: EIO", ErrorCode::IoError}), "cannot read: EIO");
  EXPECT_EQ(describe_read_error({"anything"}), "anything");

  // A stream reader's error on a foreign file, described, is what doctor says of it.
  const std::string text = "name,value\n1,2\n";
  auto foreign = make_buffer_source(Bytes(reinterpret_cast<const std::byte*>(text.data()),
                                          reinterpret_cast<const std::byte*>(text.data()) + text.size()));
  const Status magic = check_magic(*foreign, 0);
  EXPECT_EQ(describe_read_error(magic.error()), "not an MCAP file: the leading magic bytes are wrong");
}

TEST(ByteSource, FileAndBufferSourcesGiveTheSameRecords) {
  const Bytes file = recording();
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("rbsim_record_reader_test_" + std::to_string(::getpid()) + ".mcap"))
                               .string();
  {
    std::FILE* f = std::fopen(path.c_str(), "wb");
    ASSERT_NE(f, nullptr);
    ASSERT_EQ(std::fwrite(file.data(), 1, file.size(), f), file.size());
    std::fclose(f);
  }
  auto from_file = open_file_source(path);
  ASSERT_TRUE(from_file.ok()) << from_file.error().message;
  ASSERT_EQ(from_file.value()->size(), file.size());
  auto from_buffer = make_buffer_source(file);
  ViewSource from_view(file);
  std::vector<Bytes> file_contents, buffer_contents, view_contents;
  const auto a = all_records(*from_file.value(), kMagicSize, file.size() - kMagicSize, &file_contents);
  const auto b = all_records(*from_buffer, kMagicSize, file.size() - kMagicSize, &buffer_contents);
  const auto c = all_records(from_view, kMagicSize, file.size() - kMagicSize, &view_contents);
  ASSERT_FALSE(a.empty());
  ASSERT_EQ(a.size(), b.size());
  ASSERT_EQ(a.size(), c.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].opcode, b[i].opcode);
    EXPECT_EQ(a[i].offset, b[i].offset);
    EXPECT_EQ(a[i].length, b[i].length);
    EXPECT_TRUE(std::equal(std::begin(a[i].prefix), std::end(a[i].prefix), std::begin(b[i].prefix)));
    EXPECT_EQ(file_contents[i], buffer_contents[i]) << i;
    EXPECT_EQ(view_contents[i], buffer_contents[i]) << i;
  }
  EXPECT_EQ(open_file_source(path + ".missing").code(), ErrorCode::IoError);
  std::remove(path.c_str());
}

TEST(OpcodeOf, MatchesTheOpcodesOfParsedRecords) {
  EXPECT_EQ(opcode_of<Header>(), 0x01);
  EXPECT_EQ(opcode_of<Chunk>(), 0x06);
  EXPECT_EQ(opcode_of<DataEnd>(), 0x0F);
  EXPECT_EQ(opcode_of(Record{Statistics{}}), opcode_of<Statistics>());
  EXPECT_EQ(opcode_of(Record{MessageIndex{}}), opcode_of<MessageIndex>());
  EXPECT_EQ(opcode_name(opcode_of<SummaryOffset>()), "SummaryOffset");
  EXPECT_EQ(opcode_name(0x42), "opcode 0x42");
  EXPECT_FALSE(is_known_opcode(0x00));
  EXPECT_TRUE(is_known_opcode(0x0F));
  EXPECT_FALSE(is_known_opcode(0x10));
  EXPECT_FALSE(is_private_opcode(0x7F));
  EXPECT_TRUE(is_private_opcode(0x80));
}

}  // namespace
}  // namespace rbsim::mcap::test
