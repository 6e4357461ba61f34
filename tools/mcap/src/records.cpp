// Record (de)serialisation: one function per record layout of the spec's "Records" section.
#include <libdeflate.h>

#include <array>
#include <cstdio>

#include "rbsim/mcap_records.hpp"

#include "wire.hpp"

namespace rbsim::mcap {
namespace {

using detail::Cursor;

Error malformed(std::string_view type) {
  return Error{std::string(type) + " record is too short for its fields", ErrorCode::Malformed};
}

// Each parse_* reads the known fields in wire order and ignores whatever follows them (spec:
// "Records may be extended by adding new fields at the end").
bool parse(Cursor& c, Header& r) {
  return c.string(r.profile) && c.string(r.library);
}
bool parse(Cursor& c, Footer& r) {
  return c.u64(r.summary_start) && c.u64(r.summary_offset_start) && c.u32(r.summary_crc);
}
bool parse(Cursor& c, Schema& r) {
  return c.u16(r.id) && c.string(r.name) && c.string(r.encoding) && c.bytes32(r.data);
}
bool parse(Cursor& c, Channel& r) {
  return c.u16(r.id) && c.u16(r.schema_id) && c.string(r.topic) && c.string(r.message_encoding) &&
         c.string_map(r.metadata);
}
bool parse(Cursor& c, Message& r) {
  return c.u16(r.channel_id) && c.u32(r.sequence) && c.u64(r.log_time) && c.u64(r.publish_time) &&
         c.rest(r.data);
}
// A Chunk's fields before its records (parse and parse_chunk_view).
bool parse_head(Cursor& c, Chunk& r) {
  return c.u64(r.message_start_time) && c.u64(r.message_end_time) && c.u64(r.uncompressed_size) &&
         c.u32(r.uncompressed_crc) && c.string(r.compression);
}
bool parse(Cursor& c, Chunk& r) {
  return parse_head(c, r) && c.bytes64(r.records);
}
bool parse(Cursor& c, MessageIndex& r) {
  return c.u16(r.channel_id) && c.time_offsets(r.records);
}
bool parse(Cursor& c, ChunkIndex& r) {
  return c.u64(r.message_start_time) && c.u64(r.message_end_time) && c.u64(r.chunk_start_offset) &&
         c.u64(r.chunk_length) && c.id_map(r.message_index_offsets) && c.u64(r.message_index_length) &&
         c.string(r.compression) && c.u64(r.compressed_size) && c.u64(r.uncompressed_size);
}
bool parse(Cursor& c, Attachment& r) {
  return c.u64(r.log_time) && c.u64(r.create_time) && c.string(r.name) && c.string(r.media_type) &&
         c.bytes64(r.data) && c.u32(r.crc);
}
bool parse(Cursor& c, AttachmentIndex& r) {
  return c.u64(r.offset) && c.u64(r.length) && c.u64(r.log_time) && c.u64(r.create_time) &&
         c.u64(r.data_size) && c.string(r.name) && c.string(r.media_type);
}
bool parse(Cursor& c, Statistics& r) {
  return c.u64(r.message_count) && c.u16(r.schema_count) && c.u32(r.channel_count) &&
         c.u32(r.attachment_count) && c.u32(r.metadata_count) && c.u32(r.chunk_count) &&
         c.u64(r.message_start_time) && c.u64(r.message_end_time) && c.id_map(r.channel_message_counts);
}
bool parse(Cursor& c, Metadata& r) {
  return c.string(r.name) && c.string_map(r.metadata);
}
bool parse(Cursor& c, MetadataIndex& r) {
  return c.u64(r.offset) && c.u64(r.length) && c.string(r.name);
}
bool parse(Cursor& c, SummaryOffset& r) {
  return c.u8(r.group_opcode) && c.u64(r.group_start) && c.u64(r.group_length);
}
bool parse(Cursor& c, DataEnd& r) {
  return c.u32(r.data_section_crc);
}

template <typename T>
Result<Record> parse_as(ByteView content, std::string_view name) {
  Cursor c(content);
  T r;
  if (!parse(c, r)) return malformed(name);
  return Record(std::move(r));
}

}  // namespace

namespace detail {

Status parse_chunk_view(ByteView content, Chunk& r, ByteView& records) {
  Cursor c(content);
  std::uint64_t n = 0;
  if (!(parse_head(c, r) && c.u64(n) && c.view(n, records))) {
    return malformed("Chunk");
  }
  r.records.clear();
  return Ok{};
}

Status parse_message_into(ByteView content, Message& r) {
  Cursor c(content);
  if (!parse(c, r)) return malformed("Message");
  return Ok{};
}

}  // namespace detail

namespace {

using namespace detail;

void body(Bytes& o, const Header& r) {
  put_string(o, r.profile);
  put_string(o, r.library);
}
void body(Bytes& o, const Footer& r) {
  put_u64(o, r.summary_start);
  put_u64(o, r.summary_offset_start);
  put_u32(o, r.summary_crc);
}
void body(Bytes& o, const Schema& r) {
  put_u16(o, r.id);
  put_string(o, r.name);
  put_string(o, r.encoding);
  put_bytes32(o, r.data);
}
void body(Bytes& o, const Channel& r) {
  put_u16(o, r.id);
  put_u16(o, r.schema_id);
  put_string(o, r.topic);
  put_string(o, r.message_encoding);
  put_string_map(o, r.metadata);
}
void body(Bytes& o, const Message& r) {
  put_u16(o, r.channel_id);
  put_u32(o, r.sequence);
  put_u64(o, r.log_time);
  put_u64(o, r.publish_time);
  put_raw(o, r.data);
}
void body(Bytes& o, const Chunk& r) {
  put_u64(o, r.message_start_time);
  put_u64(o, r.message_end_time);
  put_u64(o, r.uncompressed_size);
  put_u32(o, r.uncompressed_crc);
  put_string(o, r.compression);
  put_bytes64(o, r.records);
}
void body(Bytes& o, const MessageIndex& r) {
  put_u16(o, r.channel_id);
  put_u32(o, static_cast<std::uint32_t>(r.records.size() * 16));
  for (const auto& [t, off] : r.records) {
    put_u64(o, t);
    put_u64(o, off);
  }
}
void body(Bytes& o, const ChunkIndex& r) {
  put_u64(o, r.message_start_time);
  put_u64(o, r.message_end_time);
  put_u64(o, r.chunk_start_offset);
  put_u64(o, r.chunk_length);
  put_id_map(o, r.message_index_offsets);
  put_u64(o, r.message_index_length);
  put_string(o, r.compression);
  put_u64(o, r.compressed_size);
  put_u64(o, r.uncompressed_size);
}
void body(Bytes& o, const Attachment& r) {
  put_u64(o, r.log_time);
  put_u64(o, r.create_time);
  put_string(o, r.name);
  put_string(o, r.media_type);
  put_bytes64(o, r.data);
  put_u32(o, r.crc);
}
void body(Bytes& o, const AttachmentIndex& r) {
  put_u64(o, r.offset);
  put_u64(o, r.length);
  put_u64(o, r.log_time);
  put_u64(o, r.create_time);
  put_u64(o, r.data_size);
  put_string(o, r.name);
  put_string(o, r.media_type);
}
void body(Bytes& o, const Statistics& r) {
  put_u64(o, r.message_count);
  put_u16(o, r.schema_count);
  put_u32(o, r.channel_count);
  put_u32(o, r.attachment_count);
  put_u32(o, r.metadata_count);
  put_u32(o, r.chunk_count);
  put_u64(o, r.message_start_time);
  put_u64(o, r.message_end_time);
  put_id_map(o, r.channel_message_counts);
}
void body(Bytes& o, const Metadata& r) {
  put_string(o, r.name);
  put_string_map(o, r.metadata);
}
void body(Bytes& o, const MetadataIndex& r) {
  put_u64(o, r.offset);
  put_u64(o, r.length);
  put_string(o, r.name);
}
void body(Bytes& o, const SummaryOffset& r) {
  put_u8(o, r.group_opcode);
  put_u64(o, r.group_start);
  put_u64(o, r.group_length);
}
void body(Bytes& o, const DataEnd& r) {
  put_u32(o, r.data_section_crc);
}
void body(Bytes& o, const UnknownRecord& r) {
  put_raw(o, r.data);
}

constexpr std::array<std::string_view, 16> kNames = {
    "Unknown",  "Header",        "Footer",        "Schema",     "Channel",         "Message",
    "Chunk",    "MessageIndex",  "ChunkIndex",    "Attachment", "AttachmentIndex", "Statistics",
    "Metadata", "MetadataIndex", "SummaryOffset", "DataEnd"};

}  // namespace

std::uint8_t opcode_of(const Record& record) {
  if (const auto* u = std::get_if<UnknownRecord>(&record)) return u->opcode;
  // Variant alternatives 0..14 are declared in opcode order 0x01..0x0F.
  return static_cast<std::uint8_t>(record.index() + 1);
}

std::string_view record_type_name(const Record& record) {
  const std::uint8_t op = opcode_of(record);
  return std::holds_alternative<UnknownRecord>(record) || op >= kNames.size() ? kNames[0] : kNames[op];
}

std::string opcode_name(std::uint8_t opcode) {
  if (opcode >= 1 && opcode < kNames.size()) return std::string(kNames[opcode]);
  char buf[24];
  std::snprintf(buf, sizeof buf, "opcode 0x%02x", opcode);
  return buf;
}

Result<Record> parse_record(std::uint8_t opcode, ByteView content) {
  switch (static_cast<Opcode>(opcode)) {
    case Opcode::Header:
      return parse_as<Header>(content, "Header");
    case Opcode::Footer:
      return parse_as<Footer>(content, "Footer");
    case Opcode::Schema:
      return parse_as<Schema>(content, "Schema");
    case Opcode::Channel:
      return parse_as<Channel>(content, "Channel");
    case Opcode::Message:
      return parse_as<Message>(content, "Message");
    case Opcode::Chunk:
      return parse_as<Chunk>(content, "Chunk");
    case Opcode::MessageIndex:
      return parse_as<MessageIndex>(content, "MessageIndex");
    case Opcode::ChunkIndex:
      return parse_as<ChunkIndex>(content, "ChunkIndex");
    case Opcode::Attachment:
      return parse_as<Attachment>(content, "Attachment");
    case Opcode::AttachmentIndex:
      return parse_as<AttachmentIndex>(content, "AttachmentIndex");
    case Opcode::Statistics:
      return parse_as<Statistics>(content, "Statistics");
    case Opcode::Metadata:
      return parse_as<Metadata>(content, "Metadata");
    case Opcode::MetadataIndex:
      return parse_as<MetadataIndex>(content, "MetadataIndex");
    case Opcode::SummaryOffset:
      return parse_as<SummaryOffset>(content, "SummaryOffset");
    case Opcode::DataEnd:
      return parse_as<DataEnd>(content, "DataEnd");
  }
  return Record(UnknownRecord{opcode, Bytes(content.begin(), content.end())});
}

void serialize_record(const Record& record, Bytes& out) {
  out.push_back(std::byte{opcode_of(record)});
  const std::size_t length_at = out.size();
  put_u64(out, 0);
  std::visit([&out](const auto& r) { body(out, r); }, record);
  const std::uint64_t n = out.size() - length_at - 8;
  for (std::size_t i = 0; i < 8; ++i) out[length_at + i] = static_cast<std::byte>(n >> (8 * i));
}

std::uint32_t crc32(ByteView data, std::uint32_t crc) {
  // zlib's CRC-32 (the one the MCAP spec names), from libdeflate, which uses carry-less
  // multiplication (PCLMULQDQ) where the CPU has it and a table otherwise; same value either way.
  // Every chunk is summed twice when written or read (its records and the data section), so its
  // speed is part of the write and read rates scripts/bench-mcap reports.
  if (data.empty()) return crc;
  return libdeflate_crc32(crc, data.data(), data.size());
}

namespace {

// CRC-32 arithmetic on polynomials over GF(2) modulo the CRC's polynomial, in its reflected bit
// order: bit 31 holds the coefficient of x^0, bit 0 that of x^31.
constexpr std::uint32_t kCrcPolynomial = 0xEDB88320u;  // x^32 + ... + 1 without the x^32 term
constexpr std::uint32_t kCrcOne = 0x80000000u;         // the polynomial 1

std::uint32_t multiply_mod(std::uint32_t a, std::uint32_t b) {
  std::uint32_t product = 0;
  for (int i = 0; i < 32; ++i) {  // a's coefficient of x^i times b x^i; b steps to b x^(i+1)
    if ((a & (kCrcOne >> i)) != 0) product ^= b;
    b = (b & 1u) != 0 ? (b >> 1) ^ kCrcPolynomial : b >> 1;
  }
  return product;
}

// x^(8 n) modulo the polynomial: appending n zero bytes multiplies a (pure) CRC by it.
std::uint32_t x_pow_8n(std::uint64_t n) {
  std::uint32_t result = kCrcOne;
  std::uint32_t square = kCrcOne >> 8;  // x^8, then x^16, x^32, ...
  for (int bit = 0; bit < 64 && n != 0; ++bit, n >>= 1) {
    if ((n & 1u) != 0) result = multiply_mod(result, square);
    square = multiply_mod(square, square);
  }
  return result;
}

}  // namespace

std::uint32_t crc32_combine(std::uint32_t crc_a, std::uint32_t crc_b, std::uint64_t length_b) {
  // zlib's CRC-32 pre- and post-inverts the register; those terms cancel between crc(a ++ b) and
  // crc(b), leaving crc(a) shifted over b's length.
  return multiply_mod(crc_a, x_pow_8n(length_b)) ^ crc_b;
}

}  // namespace rbsim::mcap
