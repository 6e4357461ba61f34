// MCAP record framing: byte sources and the record reader every MCAP reader is built on.
//
// A file is magic, then records <opcode u8><length u64><content>, then magic (spec: File
// Structure); a decompressed chunk is records alone. RecordReader walks records over any
// ByteSource (a file, a buffer, a chunk's decompressed records) without parsing their content:
// StreamReader, IndexedReader and the log tools (rbsim log doctor, recover) all frame records
// through it, so no other code reads opcodes, length prefixes or magic bytes.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <type_traits>

#include "rbsim/mcap.hpp"

namespace rbsim::mcap {

// Random-access bytes: a file, a buffer, or bytes someone else owns (a decompressed chunk).
class ByteSource {
 public:
  virtual ~ByteSource() = default;
  virtual std::uint64_t size() const = 0;
  // Views `length` bytes at `offset`; the view stays valid until the next read. Fails (never
  // allocates) when the range lies outside the source.
  virtual Status read(std::uint64_t offset, std::uint64_t length, ByteView& out) = 0;
};

Result<std::unique_ptr<ByteSource>> open_file_source(const std::string& path);
std::unique_ptr<ByteSource> make_buffer_source(Bytes data);

// Views bytes the caller keeps alive (and unchanged) while it is read, e.g. a decompressed chunk.
class ViewSource final : public ByteSource {
 public:
  explicit ViewSource(ByteView data = {}) : data_(data) {}
  void reset(ByteView data) { data_ = data; }
  std::uint64_t size() const override { return data_.size(); }
  Status read(std::uint64_t offset, std::uint64_t length, ByteView& out) override;

 private:
  ByteView data_;
};

// Checks the 8 magic bytes at `offset` (0: leading, after the Footer: trailing). BadMagic when
// the bytes there differ from kMagic, Truncated when the source ends before all 8 (the ones
// present being right), IoError when the read fails. At offset 0 the message is what
// describe_read_error words ("the leading magic bytes are wrong", "the file ends inside the
// leading magic (5 bytes)").
Status check_magic(ByteSource& source, std::uint64_t offset);
// A read error in words, the one place they are chosen (the readers' callers through
// mcap_tools::read_error, which adds the tool that helps, and doctor): what the file is by the
// error's code, then what was found. BadMagic: "not an MCAP file: MESSAGE"; Truncated:
// "truncated: MESSAGE"; CrcMismatch, DecompressionFailed, Malformed: "corrupted: MESSAGE"; any
// other code: the message alone.
std::string describe_read_error(const Error& error);
// The magic's length: where a file's first record starts, and what follows its Footer.
inline constexpr std::uint64_t kMagicSize = sizeof kMagic;

// "Chunk", "Message", ... for an opcode; "opcode 0x42" for one this library does not know.
std::string opcode_name(std::uint8_t opcode);

// Opcodes (spec: Opcodes): 0x01-0x0F are the spec's records, 0x80-0xFF private ones (readers skip
// them), the rest reserved.
constexpr bool is_known_opcode(std::uint8_t opcode) {
  return opcode >= static_cast<std::uint8_t>(Opcode::Header) &&
         opcode <= static_cast<std::uint8_t>(Opcode::DataEnd);
}
constexpr bool is_private_opcode(std::uint8_t opcode) {
  return opcode >= 0x80;
}

// The opcode of record type T (opcode_of<Chunk>() == 0x06): for code that tells framed records
// (RecordView::opcode) apart before, or without, parsing them.
template <class T>
constexpr std::uint8_t opcode_of() {
  constexpr Opcode opcode = std::is_same_v<T, Header>            ? Opcode::Header
                            : std::is_same_v<T, Footer>          ? Opcode::Footer
                            : std::is_same_v<T, Schema>          ? Opcode::Schema
                            : std::is_same_v<T, Channel>         ? Opcode::Channel
                            : std::is_same_v<T, Message>         ? Opcode::Message
                            : std::is_same_v<T, Chunk>           ? Opcode::Chunk
                            : std::is_same_v<T, MessageIndex>    ? Opcode::MessageIndex
                            : std::is_same_v<T, ChunkIndex>      ? Opcode::ChunkIndex
                            : std::is_same_v<T, Attachment>      ? Opcode::Attachment
                            : std::is_same_v<T, AttachmentIndex> ? Opcode::AttachmentIndex
                            : std::is_same_v<T, Statistics>      ? Opcode::Statistics
                            : std::is_same_v<T, Metadata>        ? Opcode::Metadata
                            : std::is_same_v<T, MetadataIndex>   ? Opcode::MetadataIndex
                            : std::is_same_v<T, SummaryOffset>   ? Opcode::SummaryOffset
                            : std::is_same_v<T, DataEnd>         ? Opcode::DataEnd
                                                                 : Opcode{0};
  static_assert(opcode != Opcode{0}, "opcode_of<T>: T is not a record type of the spec");
  return static_cast<std::uint8_t>(opcode);
}

// One framed record; `content` views the source (valid until its next read).
struct RecordView {
  std::uint8_t opcode = 0;
  std::uint64_t offset = 0;  // of the opcode byte, in the source
  std::uint64_t length = 0;  // whole record: prefix and content
  ByteView content;
  // The opcode and length bytes as they were read (a CRC over whole records covers them).
  std::byte prefix[9] = {};
  ByteView prefix_bytes() const { return ByteView(prefix, sizeof prefix); }
};

// A record the reader could not frame: where it starts and what the bytes there say.
struct RecordProblem {
  std::uint64_t offset = 0;                     // of the record
  std::uint64_t available = 0;                  // bytes from `offset` to the end of the reader's range
  std::optional<std::uint8_t> opcode;           // when a byte is left
  std::optional<std::uint64_t> content_length;  // what the length field claims, when it is whole
  Status status;  // Truncated (prefix cut off, or a length past the end) or IoError
};

// Walks the records of [begin, end) of a source one at a time. Every length is checked against
// the bytes left before anything is read, so a corrupt length never reads past the range or
// allocates: each record consumes at least its 9-byte prefix, so a walk is bounded by its range.
class RecordReader {
 public:
  static constexpr std::uint64_t kToEnd = UINT64_MAX;  // end: the end of the source
  static constexpr std::uint64_t kPrefixSize = 9;      // opcode u8 + content length u64

  using ProblemCallback = std::function<void(const RecordProblem&)>;

  explicit RecordReader(ByteSource& source, std::uint64_t begin = 0, std::uint64_t end = kToEnd)
      : source_(&source) {
    reset(begin, end);
  }
  // Reads [begin, end) of the same source from its start (clears any problem).
  void reset(std::uint64_t begin, std::uint64_t end = kToEnd);
  void reset(ByteSource& source, std::uint64_t begin = 0, std::uint64_t end = kToEnd) {
    source_ = &source;
    reset(begin, end);
  }
  // Called with each problem as it is found (before next() returns false), e.g. to word it, or to
  // resync: after a problem a caller may seek() past the bad bytes and read on.
  void on_problem(ProblemCallback callback) { on_problem_ = std::move(callback); }

  // Frames the record at position() into `out` and moves past it. False at the end of the range
  // (status() ok) or on a problem (status() and problem() say what; position() stays at the
  // record that could not be framed).
  bool next(RecordView& out);
  // Continues at `offset` (within the range): clears the problem.
  void seek(std::uint64_t offset);

  std::uint64_t position() const { return position_; }
  std::uint64_t end() const { return end_; }
  bool at_end() const { return position_ >= end_; }
  const Status& status() const { return problem_.status; }
  const RecordProblem& problem() const { return problem_; }

 private:
  bool fail(RecordProblem problem);

  ByteSource* source_;
  std::uint64_t position_ = 0;
  std::uint64_t end_ = 0;
  RecordProblem problem_;
  ProblemCallback on_problem_;
};

// The one record at `offset` (to the end of the source): RecordReader's checks and messages.
Status read_record(ByteSource& source, std::uint64_t offset, RecordView& out);

// The Footer at its fixed place before the trailing magic (spec: Footer): Truncated when the
// source is too short for magic, Header and Footer or lacks the trailing magic, Malformed when no
// Footer record ends there.
Result<Footer> read_footer(ByteSource& source);
// Where read_footer() looks: the Footer record's offset in a source of `size` bytes.
std::uint64_t footer_offset(std::uint64_t size);

}  // namespace rbsim::mcap
