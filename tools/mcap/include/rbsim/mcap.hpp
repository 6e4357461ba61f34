// MCAP container format: writer, streaming reader and indexed reader.
//
// Follows the MCAP specification (major version 0, https://mcap.dev/spec). Section names in the
// comments below ("spec: Chunk") refer to that document. All integers are little-endian; strings,
// maps and arrays carry a uint32 byte-length prefix; every record is <opcode u8><length u64><content>.
//
// No exceptions cross this API: fallible calls return a [[nodiscard]] rbsim::Status or Result<T>
// (rbsim/status.hpp), whose Error carries an ErrorCode (BadMagic, Truncated, CrcMismatch, ...).
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

#include "rbsim/bytes.hpp"
#include "rbsim/status.hpp"

namespace rbsim::mcap::detail {
class Decompressor;
}  // namespace rbsim::mcap::detail

namespace rbsim::mcap {

using rbsim::Bytes;
using rbsim::ByteView;
using Timestamp = std::uint64_t;  // nanoseconds since a user-chosen epoch
using KeyValueMap = std::map<std::string, std::string>;

// Leading and trailing bytes of every file: 0x89 "MCAP" '0' (major version) "\r\n".
inline constexpr std::byte kMagic[8] = {std::byte{0x89}, std::byte{'M'},  std::byte{'C'},  std::byte{'A'},
                                        std::byte{'P'},  std::byte{0x30}, std::byte{'\r'}, std::byte{'\n'}};
inline constexpr Timestamp kMaxTime = UINT64_MAX;

// ---------------------------------------------------------------------------------------------
// Records (spec: Records). Field order follows the wire layout.

enum class Opcode : std::uint8_t {
  Header = 0x01,
  Footer = 0x02,
  Schema = 0x03,
  Channel = 0x04,
  Message = 0x05,
  Chunk = 0x06,
  MessageIndex = 0x07,
  ChunkIndex = 0x08,
  Attachment = 0x09,
  AttachmentIndex = 0x0A,
  Statistics = 0x0B,
  Metadata = 0x0C,
  MetadataIndex = 0x0D,
  SummaryOffset = 0x0E,
  DataEnd = 0x0F,
};

struct Header {
  std::string profile;
  std::string library;
};

struct Footer {
  std::uint64_t summary_start = 0;         // 0: no summary section
  std::uint64_t summary_offset_start = 0;  // 0: no summary offset section
  std::uint32_t summary_crc = 0;           // 0: not available
};

struct Schema {
  std::uint16_t id = 0;  // 0 is invalid
  std::string name;
  std::string encoding;
  Bytes data;
};

struct Channel {
  std::uint16_t id = 0;
  std::uint16_t schema_id = 0;  // 0: schemaless
  std::string topic;
  std::string message_encoding;
  KeyValueMap metadata;
};

struct Message {
  std::uint16_t channel_id = 0;
  std::uint32_t sequence = 0;
  Timestamp log_time = 0;
  Timestamp publish_time = 0;
  Bytes data;  // rest of the record: Message records are never extended
};

struct Chunk {
  Timestamp message_start_time = 0;
  Timestamp message_end_time = 0;
  std::uint64_t uncompressed_size = 0;
  std::uint32_t uncompressed_crc = 0;  // 0: not available
  std::string compression;             // "", "lz4" (LZ4 frame) or "zstd"
  Bytes records;                       // compressed <opcode><length><content>... sequence
};

struct MessageIndex {
  std::uint16_t channel_id = 0;
  // (log_time, offset of the Message record in the uncompressed chunk records)
  std::vector<std::pair<Timestamp, std::uint64_t>> records;
};

struct ChunkIndex {
  Timestamp message_start_time = 0;
  Timestamp message_end_time = 0;
  std::uint64_t chunk_start_offset = 0;
  std::uint64_t chunk_length = 0;  // whole record, opcode and length prefix included
  std::map<std::uint16_t, std::uint64_t> message_index_offsets;  // channel id -> file offset
  std::uint64_t message_index_length = 0;
  std::string compression;
  std::uint64_t compressed_size = 0;
  std::uint64_t uncompressed_size = 0;
};

struct Attachment {
  Timestamp log_time = 0;
  Timestamp create_time = 0;
  std::string name;
  std::string media_type;
  Bytes data;
  std::uint32_t crc = 0;  // CRC-32 of all preceding fields; 0: not available
};

struct AttachmentIndex {
  std::uint64_t offset = 0;
  std::uint64_t length = 0;
  Timestamp log_time = 0;
  Timestamp create_time = 0;
  std::uint64_t data_size = 0;
  std::string name;
  std::string media_type;
};

struct Statistics {
  std::uint64_t message_count = 0;
  std::uint16_t schema_count = 0;
  std::uint32_t channel_count = 0;
  std::uint32_t attachment_count = 0;
  std::uint32_t metadata_count = 0;
  std::uint32_t chunk_count = 0;
  Timestamp message_start_time = 0;
  Timestamp message_end_time = 0;
  std::map<std::uint16_t, std::uint64_t> channel_message_counts;
};

struct Metadata {
  std::string name;
  KeyValueMap metadata;
};

struct MetadataIndex {
  std::uint64_t offset = 0;
  std::uint64_t length = 0;
  std::string name;
};

struct SummaryOffset {
  std::uint8_t group_opcode = 0;
  std::uint64_t group_start = 0;
  std::uint64_t group_length = 0;
};

struct DataEnd {
  std::uint32_t data_section_crc = 0;  // CRC-32 of every byte before this record; 0: not available
};

// Any opcode this library does not know (0x80-0xFF are application extensions).
struct UnknownRecord {
  std::uint8_t opcode = 0;
  Bytes data;
};

using Record =
    std::variant<Header, Footer, Schema, Channel, Message, Chunk, MessageIndex, ChunkIndex, Attachment,
                 AttachmentIndex, Statistics, Metadata, MetadataIndex, SummaryOffset, DataEnd, UnknownRecord>;

std::uint8_t opcode_of(const Record& record);
// "Header", "Chunk", ... (the spec's record names without spaces); "Unknown" otherwise.
std::string_view record_type_name(const Record& record);

// Parses one record's content (the bytes after opcode and length). Fields past the known ones
// are ignored, as the spec requires for forward compatibility.
Result<Record> parse_record(std::uint8_t opcode, ByteView content);
// Appends <opcode><length><content> for `record`.
void serialize_record(const Record& record, Bytes& out);

// CRC-32 as in zlib (polynomial 0xEDB88320); chainable: crc32(b, crc32(a)) == crc32(a ++ b).
std::uint32_t crc32(ByteView data, std::uint32_t crc = 0);
// The CRC-32 of a ++ b from crc32(a), crc32(b) and b's length, without reading either.
std::uint32_t crc32_combine(std::uint32_t crc_a, std::uint32_t crc_b, std::uint64_t length_b);

enum class Compression : std::uint8_t { None, Lz4, Zstd };
std::string_view to_string(Compression compression);  // "", "lz4", "zstd"
// A CRC-32 as every rbsim tool prints one: "0x" and 8 lowercase hex digits.
std::string crc_text(std::uint32_t crc);
// Parses a codec's command-line name: "zstd", "lz4", "none".
bool parse_compression(std::string_view name, Compression& out);
// Empty when `level` suits the codec: zstd -50..22 (negative: faster, larger), lz4 0..12 (frame
// compression levels; 3 and up are LZ4-HC), none 0 only. Otherwise what is wrong.
std::string check_compression_level(Compression compression, int level);

// Decompresses chunk.records into `out`, checking the size against uncompressed_size and, when
// verify_crc and the chunk has one, the CRC. Never allocates much beyond the real output.
Status decompress_chunk(const Chunk& chunk, Bytes& out, bool verify_crc = true);
// The same for chunk after chunk, keeping the codec contexts between them (with an `out` kept
// between calls too, nothing is allocated once the largest chunk was seen): a tool that checks or
// reads many chunks on one thread.
class ChunkDecompressor {
 public:
  ChunkDecompressor();
  ~ChunkDecompressor();
  ChunkDecompressor(const ChunkDecompressor&) = delete;
  ChunkDecompressor& operator=(const ChunkDecompressor&) = delete;
  Status decompress(const Chunk& chunk, Bytes& out, bool verify_crc = true);

 private:
  std::unique_ptr<detail::Decompressor> impl_;
};

// ---------------------------------------------------------------------------------------------
// Writer

struct WriterOptions {
  std::string profile;
  std::string library = "rbsim-mcap";
  Compression compression = Compression::Zstd;
  int compression_level = 0;  // 0: the MCAP C++ library's default (zstd 1, lz4 frame default)
  bool use_chunks = true;
  std::uint64_t chunk_size = 1024 * 1024;  // uncompressed bytes after which a chunk is flushed
  bool emit_message_indexes = true;
  bool emit_chunk_indexes = true;
  bool emit_attachment_indexes = true;
  bool emit_metadata_indexes = true;
  bool emit_statistics = true;
  bool emit_summary_offsets = true;
  bool repeat_schemas = true;   // copy Schema records into the summary
  bool repeat_channels = true;  // copy Channel records into the summary
  bool enable_crcs = true;      // chunk, attachment, data section and summary CRCs
  // Compress each full chunk (and take its CRC) on a second thread while the next one fills; a
  // chunk that fills while that thread is still busy is compressed on the caller's meanwhile. Same
  // bytes as without; a completed chunk reaches the file once compressed, or at the next write
  // or flush after that, so a killed process may lose one more chunk than without. Uncompressed
  // chunks written to a regular file (or memory) are streamed instead (see writer.cpp): no thread.
  bool background_compression = false;
};

class Writer {
 public:
  Writer();
  ~Writer();  // closes if still open, ignoring errors
  Writer(const Writer&) = delete;
  Writer& operator=(const Writer&) = delete;

  // Writes magic + Header. Completed chunks are flushed to the OS as they are written, so a
  // killed process leaves a file whose complete chunks can be read (and recovered).
  Status open(const std::string& path, const WriterOptions& options = {});
  // Same, into memory; read the bytes with buffer() after close().
  Status open_buffer(const WriterOptions& options = {});

  // Ids are assigned from 1 upwards (one past the largest id in use).
  Result<std::uint16_t> add_schema(std::string_view name, std::string_view encoding, ByteView data);
  // schema_id 0 means schemaless.
  Result<std::uint16_t> add_channel(std::uint16_t schema_id, std::string_view topic,
                                    std::string_view message_encoding, const KeyValueMap& metadata = {});
  // With the record's own id (e.g. when copying a file); re-adding an identical record is a no-op,
  // a different record under a used id is an error (spec: Schema, Channel).
  Status add_schema(const Schema& schema);
  Status add_channel(const Channel& channel);
  Status write_message(std::uint16_t channel_id, std::uint32_t sequence, Timestamp log_time,
                       Timestamp publish_time, ByteView data);
  Status write_message(const Message& message);
  Status add_attachment(Timestamp log_time, Timestamp create_time, std::string_view name,
                        std::string_view media_type, ByteView data);
  Status add_metadata(std::string_view name, const KeyValueMap& metadata);
  // Copies a complete chunk of another file as it is stored (no decompression), after the pending
  // chunk, with its message indexes (offsets into its records, as read): a tool that keeps whole
  // chunks of a file. Its compression must be this writer's, and every channel its indexes name
  // must have been added with the same id (its records are not rewritten).
  Status copy_chunk(const Chunk& chunk, const std::vector<MessageIndex>& indexes);
  // Writes the pending chunk now (a recorder may call this periodically to bound loss).
  Status flush_chunk();
  // With background_compression: writes a chunk whose compression has finished, without waiting
  // (write_message does this too; a writer that may sit idle calls it so the chunk reaches the file).
  Status write_compressed_chunk();
  // Writes the last chunk, DataEnd, summary, summary offsets, Footer and magic.
  Status close();

  bool is_open() const;
  const Statistics& statistics() const;
  const Bytes& buffer() const;  // open_buffer() output

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// ---------------------------------------------------------------------------------------------
// Streaming reader: every record in file order.

struct StreamOptions {
  bool descend_into_chunks = true;  // report the records inside each Chunk
  bool report_chunks = false;       // also report the Chunk record itself (before its contents)
  bool report_message_indexes = false;
  bool verify_crcs = true;  // chunk, data section and summary CRCs (when non-zero in the file)
};

struct RecordEntry {
  Record record;
  // Top-level records: file offset. Records inside a chunk: offset in the uncompressed records.
  std::uint64_t offset = 0;
  std::uint64_t length = 0;                   // whole record, opcode and length prefix included
  std::optional<std::uint64_t> chunk_offset;  // file offset of the enclosing Chunk, if any
};

class StreamReader {
 public:
  StreamReader();
  ~StreamReader();
  StreamReader(const StreamReader&) = delete;
  StreamReader& operator=(const StreamReader&) = delete;

  Status open(const std::string& path, const StreamOptions& options = {});
  Status open_buffer(Bytes data, const StreamOptions& options = {});

  // Fills `out` with the next record. Returns false at the end or on error: then check status().
  // A file that stops before its Footer and trailing magic ends with ErrorCode::Truncated after
  // every complete record was reported. The first failure ends the stream (a recover tool reads
  // what came before it).
  bool next(RecordEntry& out);
  const Status& status() const;
  // File offset of the next top-level record to read (or of the failure).
  std::uint64_t position() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// ---------------------------------------------------------------------------------------------
// Indexed reader: footer -> summary -> chunk indexes -> only the chunks a query needs.

struct IndexedOptions {
  bool verify_summary_crc = true;
  bool verify_chunk_crcs = true;
};

struct ReadMessagesOptions {
  std::vector<std::string> topics;              // empty: all topics
  Timestamp start_time = 0;                     // inclusive
  Timestamp end_time = kMaxTime;                // exclusive (kMaxTime: no upper bound)
  std::vector<std::uint64_t> skip_chunks = {};  // chunks (by file offset) not to read (indexed files)
};

struct MessageEntry {
  const Message& message;
  const Channel* channel = nullptr;  // null if the file never defined the channel
  const Schema* schema = nullptr;    // null for schemaless channels
  std::optional<std::uint64_t> chunk_offset;
};

class IndexedReader {
 public:
  IndexedReader();
  ~IndexedReader();
  IndexedReader(const IndexedReader&) = delete;
  IndexedReader& operator=(const IndexedReader&) = delete;

  // Reads magic, Header, Footer and the summary (checking its CRC). Files whose summary has no chunk
  // indexes are still readable: open() and each query then scan the file linearly. With chunk
  // indexes, messages outside chunks are not seen (the spec keeps every message of an indexed file
  // in a chunk), and schemas()/channels() grow with the Schema/Channel records of chunks read.
  Status open(const std::string& path, const IndexedOptions& options = {});
  Status open_buffer(Bytes data, const IndexedOptions& options = {});

  // Calls `on_message` for every matching message in log-time order; equal times keep file order.
  // Returning false from the callback stops early (not an error).
  Status read_messages(const ReadMessagesOptions& options,
                       const std::function<bool(const MessageEntry&)>& on_message);
  Result<std::vector<Message>> read_all_messages(const ReadMessagesOptions& options = {});

  // The Chunk record `index` points at, as stored (compressed); with verify it is decompressed
  // once to check its size and CRC (then dropped). For Writer::copy_chunk.
  Result<Chunk> read_chunk(const ChunkIndex& index, bool verify = true);
  // The message indexes of that chunk (spec: Message Index), one per channel it lists.
  Result<std::vector<MessageIndex>> read_message_indexes(const ChunkIndex& index);
  Result<Attachment> read_attachment(const AttachmentIndex& index);
  Result<Metadata> read_metadata(const MetadataIndex& index);
  // Checks DataEnd.data_section_crc against the bytes before it (reads the whole data section).
  Status verify_data_section_crc();

  bool indexed() const;  // true when the summary has chunk indexes
  std::uint64_t file_size() const;
  const Header& header() const;
  const Footer& footer() const;
  const std::map<std::uint16_t, Schema>& schemas() const;
  const std::map<std::uint16_t, Channel>& channels() const;
  const std::vector<ChunkIndex>& chunk_indexes() const;
  const std::vector<AttachmentIndex>& attachment_indexes() const;
  const std::vector<MetadataIndex>& metadata_indexes() const;
  const std::vector<SummaryOffset>& summary_offsets() const;
  const std::optional<Statistics>& statistics() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rbsim::mcap
