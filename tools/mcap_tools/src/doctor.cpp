// rbsim log doctor: the checks of the official `mcap doctor` (go/cli/mcap/cmd/doctor.go) plus
// the ones it leaves out (data section and summary CRCs, message index entries that point at no
// message, chunk index message-index offsets and lengths, statistics counts of schemas, channels,
// chunks, attachments and metadata, summary offsets, attachment and metadata indexes).
//
// One pass over the file record by record, then the summary checks. Every loop is bounded by the
// bytes it reads: each record consumes at least its 9-byte prefix, and record lengths are checked
// against the bytes that remain before anything is read or allocated.
#include <algorithm>
#include <cstring>
#include <set>
#include <sstream>
#include <unordered_map>

#include "rbsim/mcap_tools.hpp"
#include "tools_util.hpp"

namespace rbsim::mcap_tools {

using detail::kPrefix;
using detail::opcode_name;

std::string DoctorReport::first_error() const {
  for (const DoctorFinding& f : findings) {
    if (f.error) return f.text;
  }
  return {};
}

namespace {

constexpr std::size_t kMaxFindings = 1000;  // further findings are counted, not stored

template <class... A>
std::string cat(const A&... a) {
  std::ostringstream s;
  (s << ... << a);
  return s.str();
}

std::string hex32(std::uint32_t v) {
  return mcap::crc_text(v);
}

constexpr std::uint8_t op(mcap::Opcode o) {
  return static_cast<std::uint8_t>(o);
}

struct ChunkInfo {
  std::uint64_t offset = 0, length = 0;  // whole record
  mcap::Timestamp start = 0, end = 0;
  std::string compression;
  std::uint64_t compressed_size = 0, uncompressed_size = 0;
  std::map<std::uint16_t, std::uint64_t> index_offsets;  // MessageIndex records that follow it
  std::uint64_t index_length = 0;
  std::set<std::uint16_t> channels;  // referenced by its messages
};

struct PendingChunk {
  mcap::Chunk chunk;
  std::uint64_t offset = 0, length = 0;
  std::map<std::uint16_t, mcap::MessageIndex> indexes;
  std::map<std::uint16_t, std::uint64_t> index_offsets;
  std::uint64_t index_length = 0;
};

struct SummaryRecord {
  std::uint8_t opcode = 0;
  std::uint64_t offset = 0, length = 0;
};

struct AttachmentSeen {
  std::uint64_t length = 0;
  mcap::Timestamp log_time = 0, create_time = 0;
  std::uint64_t data_size = 0;
  std::string name, media_type;
};

class Doctor {
 public:
  explicit Doctor(const DoctorOptions& options) : options_(options) {}
  DoctorReport run(const std::string& path);

 private:
  void add(bool is_error, std::string text) {
    (is_error ? report_.errors : report_.warnings)++;
    if (report_.findings.size() < kMaxFindings) report_.findings.push_back({is_error, std::move(text)});
  }
  void error(std::string text) { add(true, std::move(text)); }
  void warn(std::string text) { add(false, std::move(text)); }

  bool lex();
  void handle(std::uint8_t opcode, const mcap::ByteView content, mcap::Record& record);
  void examine_schema(const mcap::Schema& schema);
  void examine_channel(const mcap::Channel& channel);
  void examine_chunk(PendingChunk& p);
  void flush_chunk() {
    if (pending_) {
      examine_chunk(*pending_);
      pending_.reset();
    }
  }
  void check_footer_offsets();
  void check_summary_offsets();
  void check_chunk_indexes();
  void check_statistics();
  void check_attachment_and_metadata_indexes();
  std::string topic_of(std::uint16_t channel_id) const {
    auto it = channels_.find(channel_id);
    return it == channels_.end() ? std::string("<unknown channel>") : it->second.topic;
  }

  DoctorOptions options_;
  DoctorReport report_;
  detail::FileBytes file_;
  std::uint64_t size_ = 0;
  std::uint64_t pos_ = 0;  // offset of the record being handled

  bool in_summary_ = false;
  bool seen_header_ = false;
  std::optional<mcap::DataEnd> data_end_;
  std::uint64_t summary_begin_ = 0;
  std::optional<mcap::Footer> footer_;
  std::uint64_t footer_offset_ = 0;
  std::uint32_t data_crc_ = 0, summary_crc_ = 0;
  bool message_outside_chunk_ = false, warned_outside_chunk_ = false;
  mcap::Timestamp last_message_time_ = 0;  // top-level messages

  std::map<std::uint16_t, mcap::Schema> schemas_;    // data section
  std::map<std::uint16_t, mcap::Channel> channels_;  // data section
  std::set<std::uint16_t> summary_schema_ids_, summary_channel_ids_;

  std::optional<PendingChunk> pending_;
  std::map<std::uint64_t, ChunkInfo> chunks_;  // by offset
  std::map<std::uint64_t, mcap::ChunkIndex> chunk_indexes_;
  std::map<std::uint64_t, AttachmentSeen> attachments_;                      // by offset
  std::map<std::uint64_t, std::pair<std::uint64_t, std::string>> metadata_;  // offset -> (length, name)
  std::vector<std::pair<std::uint64_t, mcap::AttachmentIndex>> attachment_indexes_;
  std::vector<std::pair<std::uint64_t, mcap::MetadataIndex>> metadata_indexes_;
  std::vector<SummaryRecord> summary_records_;
  std::vector<std::pair<std::uint64_t, mcap::SummaryOffset>> summary_offsets_;

  std::uint64_t message_count_ = 0;
  std::map<std::uint16_t, std::uint64_t> channel_message_counts_;
  mcap::Timestamp min_log_time_ = mcap::kMaxTime, max_log_time_ = 0;
  std::optional<mcap::Statistics> statistics_;
};

DoctorReport Doctor::run(const std::string& path) {
  if (std::string e = file_.open(path); !e.empty()) {
    error(e);
    return std::move(report_);
  }
  size_ = file_.size();
  if (lex()) {
    check_footer_offsets();
    check_summary_offsets();
    check_chunk_indexes();
    check_statistics();
    check_attachment_and_metadata_indexes();
  }
  if (report_.findings.size() < report_.errors + report_.warnings) {
    report_.findings.push_back({false, cat(report_.errors + report_.warnings - report_.findings.size(),
                                           " further findings not shown")});
  }
  return std::move(report_);
}

// The record-by-record pass. Returns false when the file could not be read to its Footer (the
// summary checks then make no sense); the reason is already reported.
bool Doctor::lex() {
  mcap::Bytes buf;
  if (size_ == 0) {
    error("empty file (0 bytes): not an MCAP file");
    return false;
  }
  const std::uint64_t head = std::min<std::uint64_t>(size_, 8);
  if (!file_.read(0, head, buf)) {
    error("cannot read the file");
    return false;
  }
  if (std::memcmp(buf.data(), mcap::kMagic, buf.size()) != 0) {
    error("not an MCAP file: the leading magic bytes are wrong");
    return false;
  }
  if (size_ < 8) {
    error(cat("truncated: the file ends inside the leading magic (", size_, " bytes)"));
    return false;
  }
  data_crc_ = mcap::crc32(buf);
  std::uint8_t last_opcode = 0;
  bool first = true;
  mcap::Bytes prefix, content;
  for (pos_ = 8; pos_ < size_;) {
    const std::uint64_t left = size_ - pos_;
    if (left < kPrefix) {
      flush_chunk();
      error(cat("truncated: the file ends inside a record header at offset ", pos_, " (", left,
                " bytes left, last record was ", opcode_name(last_opcode), ")"));
      return false;
    }
    if (!file_.read(pos_, kPrefix, prefix)) {
      error(cat("cannot read at offset ", pos_));
      return false;
    }
    const std::uint8_t opcode = prefix[0];
    const std::uint64_t length = detail::le64(prefix.data() + 1);
    if (length > left - kPrefix) {
      flush_chunk();
      error(cat("truncated: ", opcode_name(opcode), " record at offset ", pos_, " claims ", length,
                " bytes, but only ", left - kPrefix, " remain"));
      return false;
    }
    if (!file_.read(pos_ + kPrefix, length, content)) {
      error(cat("cannot read ", length, " bytes at offset ", pos_ + kPrefix));
      return false;
    }
    last_opcode = opcode;
    const bool is_footer = opcode == op(mcap::Opcode::Footer);
    if (!data_end_ && opcode != op(mcap::Opcode::DataEnd)) {
      data_crc_ = mcap::crc32(content, mcap::crc32(prefix, data_crc_));
    } else if (data_end_ && !is_footer) {
      summary_crc_ = mcap::crc32(content, mcap::crc32(prefix, summary_crc_));
    }
    if (opcode != op(mcap::Opcode::MessageIndex)) flush_chunk();
    if (first && opcode != op(mcap::Opcode::Header)) {
      error(cat("the first record is a ", opcode_name(opcode), ", not a Header"));
    }
    first = false;
    if (opcode == 0) {
      // Typically the zero-filled tail of a file whose writer died: nothing after it is a record.
      flush_chunk();
      error(cat("invalid record (opcode 0x00) at offset ", pos_,
                ": the rest of the file is not MCAP records (zero-filled?)"));
      return false;
    }
    if (opcode < 0x80 && opcode > 0x0F) {
      warn(cat("unknown record opcode 0x", std::hex, static_cast<int>(opcode), std::dec, " at offset ", pos_,
               " (ignored)"));
    } else if (opcode <= 0x0F) {
      auto parsed = mcap::parse_record(opcode, content);
      if (!parsed.ok()) {
        error(cat("failed to parse ", opcode_name(opcode), " record at offset ", pos_, ": ",
                  parsed.status().message));
      } else {
        handle(opcode, content, parsed.value());
      }
    }
    if (data_end_ && !is_footer && opcode != op(mcap::Opcode::DataEnd)) {
      summary_records_.push_back({opcode, pos_, kPrefix + length});
    }
    if (is_footer) {
      footer_offset_ = pos_;
      const std::uint64_t after = pos_ + kPrefix + length;
      if (content.size() >= 16) {
        summary_crc_ = mcap::crc32(mcap::ByteView(content).subspan(0, 16), mcap::crc32(prefix, summary_crc_));
      }
      if (size_ - after < 8) {
        error(cat("truncated: the file ends ", size_ - after, " bytes into the trailing magic"));
        return false;
      }
      if (!file_.read(after, 8, buf) || std::memcmp(buf.data(), mcap::kMagic, 8) != 0) {
        error(cat("the trailing magic bytes at offset ", after, " are wrong"));
      }
      if (size_ - after > 8) error(cat(size_ - after - 8, " unexpected bytes after the trailing magic"));
      break;
    }
    pos_ += kPrefix + length;
  }
  flush_chunk();
  if (!footer_) {
    const std::string last = last_opcode == 0 ? std::string("none") : opcode_name(last_opcode);
    error(cat("truncated: the file ends at offset ", size_, " without a Footer record (last record was ",
              last, ")"));
    if (!data_end_) error(cat("the file has no DataEnd record (last record was ", last, ")"));
    return false;
  }
  if (!data_end_) error("the file has no DataEnd record");
  if (footer_->summary_crc != 0 && footer_->summary_crc != summary_crc_) {
    error(cat("summary CRC mismatch: computed ", hex32(summary_crc_), ", Footer.summary_crc is ",
              hex32(footer_->summary_crc)));
  }
  return true;
}

void Doctor::handle(std::uint8_t opcode, const mcap::ByteView content, mcap::Record& record) {
  const std::string at = cat(" at offset ", pos_);
  auto data_only = [&] {
    if (in_summary_) error(cat(opcode_name(opcode), " record", at, " is in the summary section"));
  };
  auto summary_only = [&] {
    if (!in_summary_) {
      warn(cat(opcode_name(opcode), " record", at,
               " is in the data section (readers look for it in the summary)"));
    }
  };
  switch (static_cast<mcap::Opcode>(opcode)) {
    case mcap::Opcode::Header: {
      const auto& h = std::get<mcap::Header>(record);
      if (seen_header_ || pos_ != 8) error(cat("Header record", at, " is not the first record"));
      seen_header_ = true;
      if (h.library.empty()) {
        warn("Set the Header.library field to a value that identifies the software that produced the file.");
      }
      if (!h.profile.empty() && h.profile != "ros1" && h.profile != "ros2") {
        warn(cat("Header.profile field \"", h.profile, "\" is not a well-known profile."));
      }
      break;
    }
    case mcap::Opcode::Footer:
      footer_ = std::get<mcap::Footer>(record);
      if (!data_end_) error("Footer without a DataEnd record before it");
      break;
    case mcap::Opcode::Schema:
      examine_schema(std::get<mcap::Schema>(record));
      break;
    case mcap::Opcode::Channel:
      examine_channel(std::get<mcap::Channel>(record));
      break;
    case mcap::Opcode::Message: {
      data_only();
      const auto& m = std::get<mcap::Message>(record);
      message_outside_chunk_ = true;
      if (channels_.count(m.channel_id) == 0) {
        error(cat("Got a Message record for channel: ", m.channel_id, " before a channel info", at, "."));
      }
      if (m.log_time < last_message_time_) {
        error(cat("Message.log_time ", m.log_time, " on \"", topic_of(m.channel_id),
                  "\" is less than the previous message record time ", last_message_time_, at));
      }
      last_message_time_ = m.log_time;
      min_log_time_ = std::min(min_log_time_, m.log_time);
      max_log_time_ = std::max(max_log_time_, m.log_time);
      ++message_count_;
      ++channel_message_counts_[m.channel_id];
      break;
    }
    case mcap::Opcode::Chunk: {
      data_only();
      PendingChunk p;
      p.chunk = std::move(std::get<mcap::Chunk>(record));
      p.offset = pos_;
      p.length = kPrefix + content.size();
      pending_ = std::move(p);
      break;
    }
    case mcap::Opcode::MessageIndex: {
      data_only();
      auto& mi = std::get<mcap::MessageIndex>(record);
      if (message_outside_chunk_ && !warned_outside_chunk_) {
        warned_outside_chunk_ = true;
        warn(
            "Message index in file has message records outside chunks. Indexed readers will miss these "
            "messages.");
      }
      if (!pending_) {
        error(cat("Message index", at, " found but no chunk before it"));
      } else if (pending_->indexes.count(mi.channel_id) != 0) {
        warn(cat("Duplicate message index found for channel ", mi.channel_id, at));
      } else {
        pending_->index_offsets[mi.channel_id] = pos_;
        pending_->index_length += kPrefix + content.size();
        pending_->indexes.emplace(mi.channel_id, std::move(mi));
      }
      break;
    }
    case mcap::Opcode::ChunkIndex: {
      summary_only();
      auto& ci = std::get<mcap::ChunkIndex>(record);
      if (message_outside_chunk_ && !warned_outside_chunk_) {
        warned_outside_chunk_ = true;
        warn(
            "Message index in file has message records outside chunks. Indexed readers will miss these "
            "messages.");
      }
      if (chunk_indexes_.count(ci.chunk_start_offset) != 0) {
        error(cat("Multiple chunk indexes found for chunk at offset ", ci.chunk_start_offset));
      } else {
        chunk_indexes_.emplace(ci.chunk_start_offset, std::move(ci));
      }
      break;
    }
    case mcap::Opcode::Attachment: {
      data_only();
      const auto& a = std::get<mcap::Attachment>(record);
      if (a.crc != 0) {
        const std::size_t covered = 8 + 8 + 4 + a.name.size() + 4 + a.media_type.size() + 8 + a.data.size();
        const std::uint32_t crc = mcap::crc32(content.subspan(0, std::min(covered, content.size())));
        if (crc != a.crc) {
          error(cat("Attachment \"", a.name, "\"", at, ": invalid CRC: computed ", hex32(crc),
                    ", Attachment.crc is ", hex32(a.crc)));
        }
      }
      attachments_[pos_] = {
          kPrefix + content.size(), a.log_time, a.create_time, a.data.size(), a.name, a.media_type};
      break;
    }
    case mcap::Opcode::AttachmentIndex:
      summary_only();
      attachment_indexes_.emplace_back(pos_, std::get<mcap::AttachmentIndex>(record));
      break;
    case mcap::Opcode::Statistics:
      summary_only();
      if (statistics_) error("File contains multiple Statistics records");
      statistics_ = std::get<mcap::Statistics>(record);
      break;
    case mcap::Opcode::Metadata:
      data_only();
      metadata_[pos_] = {kPrefix + content.size(), std::get<mcap::Metadata>(record).name};
      break;
    case mcap::Opcode::MetadataIndex:
      summary_only();
      metadata_indexes_.emplace_back(pos_, std::get<mcap::MetadataIndex>(record));
      break;
    case mcap::Opcode::SummaryOffset:
      if (!in_summary_) error(cat("SummaryOffset record", at, " is in the data section"));
      summary_offsets_.emplace_back(pos_, std::get<mcap::SummaryOffset>(record));
      break;
    case mcap::Opcode::DataEnd: {
      if (data_end_) {
        error(cat("second DataEnd record", at));
        break;
      }
      data_end_ = std::get<mcap::DataEnd>(record);
      summary_begin_ = pos_ + kPrefix + content.size();
      in_summary_ = true;
      if (data_end_->data_section_crc != 0 && data_end_->data_section_crc != data_crc_) {
        error(cat("data section CRC mismatch: computed ", hex32(data_crc_), ", DataEnd.data_section_crc is ",
                  hex32(data_end_->data_section_crc)));
      }
      break;
    }
  }
}

void Doctor::examine_schema(const mcap::Schema& schema) {
  if (schema.encoding.empty()) {
    if (schema.data.empty()) {
      warn(cat("Schema with ID: ", schema.id, ", Name: \"", schema.name,
               "\" has empty Encoding and Data fields"));
    } else {
      error(cat("Schema with ID: ", schema.id, " has empty Encoding but Data contains ", schema.data.size(),
                " bytes"));
    }
  }
  if (schema.id == 0) error("Schema.ID 0 is reserved. Do not make Schema records with ID 0.");
  const auto it = schemas_.find(schema.id);
  const mcap::Schema* previous = it == schemas_.end() ? nullptr : &it->second;
  if (previous != nullptr) {
    if (schema.name != previous->name) {
      error(cat("Two schema records with same ID ", schema.id, " but different names (\"", schema.name,
                "\" != \"", previous->name, "\")"));
    }
    if (schema.encoding != previous->encoding) {
      error(cat("Two schema records with same ID ", schema.id, " but different encodings (\"",
                schema.encoding, "\" != \"", previous->encoding, "\")"));
    }
    if (schema.data != previous->data) {
      error(cat("Two schema records with different data present with same ID ", schema.id));
    }
  }
  if (in_summary_) {
    if (previous == nullptr)
      error(cat("Schema with id ", schema.id, " in summary section does not exist in data section"));
    summary_schema_ids_.insert(schema.id);
  } else {
    if (previous != nullptr) warn(cat("Duplicate schema records in data section with ID ", schema.id));
    schemas_.insert_or_assign(schema.id, schema);
  }
}

void Doctor::examine_channel(const mcap::Channel& channel) {
  const auto it = channels_.find(channel.id);
  const mcap::Channel* previous = it == channels_.end() ? nullptr : &it->second;
  if (previous != nullptr) {
    if (channel.schema_id != previous->schema_id) {
      error(cat("Two channel records with same ID ", channel.id, " but different schema IDs (",
                channel.schema_id, " != ", previous->schema_id, ")"));
    }
    if (channel.topic != previous->topic) {
      error(cat("Two channel records with same ID ", channel.id, " but different topics (\"", channel.topic,
                "\" != \"", previous->topic, "\")"));
    }
    if (channel.message_encoding != previous->message_encoding) {
      error(cat("Two channel records with same ID ", channel.id, " but different message encodings (\"",
                channel.message_encoding, "\" != \"", previous->message_encoding, "\")"));
    }
    if (channel.metadata != previous->metadata) {
      error(cat("Two channel records with different metadata present with same ID ", channel.id));
    }
  }
  if (in_summary_) {
    if (previous == nullptr)
      error(cat("Channel with ID ", channel.id, " in summary section does not exist in data section"));
    summary_channel_ids_.insert(channel.id);
  } else {
    if (previous != nullptr) warn(cat("Duplicate channel records in data section with ID ", channel.id));
    channels_.insert_or_assign(channel.id, channel);
  }
  if (channel.schema_id != 0 && schemas_.count(channel.schema_id) == 0) {
    error(cat("Encountered Channel (", channel.id, ") with unknown Schema (", channel.schema_id, ")"));
  }
}

void Doctor::examine_chunk(PendingChunk& p) {
  const mcap::Chunk& chunk = p.chunk;
  ChunkInfo& info = chunks_[p.offset];
  info.offset = p.offset;
  info.length = p.length;
  info.start = chunk.message_start_time;
  info.end = chunk.message_end_time;
  info.compression = chunk.compression;
  info.compressed_size = chunk.records.size();
  info.uncompressed_size = chunk.uncompressed_size;
  info.index_offsets = p.index_offsets;
  info.index_length = p.index_length;
  const std::string where = cat("Chunk at offset ", p.offset);

  mcap::Bytes data;
  if (mcap::Status s = mcap::decompress_chunk(chunk, data, false); !s.ok()) {
    if (s.code == mcap::StatusCode::UnsupportedCompression) {
      error(cat(where, ": Unsupported compression format: \"", chunk.compression, "\""));
    } else if (s.code == mcap::StatusCode::Malformed) {
      error(cat(where, ": Uncompressed chunk data size != Chunk.uncompressed_size (", s.message, ")"));
    } else {
      error(cat(where, ": Could not decompress: ", s.message));
    }
    return;
  }
  if (chunk.uncompressed_crc != 0) {
    const std::uint32_t crc = mcap::crc32(data);
    if (crc != chunk.uncompressed_crc) {
      error(cat(where, ": invalid CRC: computed ", hex32(crc), ", Chunk.uncompressed_crc is ",
                hex32(chunk.uncompressed_crc)));
      return;
    }
  }

  // Message index entries by channel: offset -> log time.
  std::map<std::uint16_t, std::unordered_map<std::uint64_t, mcap::Timestamp>> index_entries;
  for (const auto& [channel_id, mi] : p.indexes) {
    auto& entries = index_entries[channel_id];
    for (const auto& [t, offset] : mi.records) entries.emplace(offset, t);
  }
  std::unordered_map<std::uint64_t, std::uint16_t> message_at;  // offset -> channel
  mcap::Timestamp min_time = mcap::kMaxTime, max_time = 0;
  std::uint64_t count = 0;
  const mcap::ByteView view(data);
  for (std::size_t at = 0; at < data.size();) {
    const std::size_t left = data.size() - at;
    if (left < kPrefix) {
      error(cat(where, ": record header cut off at byte ", at, " of the uncompressed records"));
      break;
    }
    const std::uint8_t opcode = data[at];
    const std::uint64_t length = detail::le64(data.data() + at + 1);
    if (length > left - kPrefix) {
      error(cat(where, ": ", opcode_name(opcode), " record at byte ", at, " claims ", length, " bytes, only ",
                left - kPrefix, " remain in the chunk"));
      break;
    }
    const auto content = view.subspan(at + kPrefix, static_cast<std::size_t>(length));
    const std::uint64_t offset = at;
    at += kPrefix + static_cast<std::size_t>(length);
    if (opcode != op(mcap::Opcode::Schema) && opcode != op(mcap::Opcode::Channel) &&
        opcode != op(mcap::Opcode::Message)) {
      error(cat(where, ": Illegal record in chunk: ", opcode_name(opcode), " at byte ", offset));
      continue;
    }
    auto parsed = mcap::parse_record(opcode, content);
    if (!parsed.ok()) {
      error(cat(where, ": failed to parse ", opcode_name(opcode), " at byte ", offset, ": ",
                parsed.status().message));
      continue;
    }
    if (opcode == op(mcap::Opcode::Schema)) {
      examine_schema(std::get<mcap::Schema>(parsed.value()));
      continue;
    }
    if (opcode == op(mcap::Opcode::Channel)) {
      examine_channel(std::get<mcap::Channel>(parsed.value()));
      continue;
    }
    const auto& m = std::get<mcap::Message>(parsed.value());
    info.channels.insert(m.channel_id);
    message_at.emplace(offset, m.channel_id);
    if (channels_.count(m.channel_id) == 0) {
      error(cat(where, ": Got a Message record for channel: ", m.channel_id, " before a channel record."));
    }
    if (m.log_time < max_log_time_) {
      std::string text = cat("Message.log_time ", m.log_time, " on \"", topic_of(m.channel_id),
                             "\" is less than the latest log time ", max_log_time_);
      if (options_.strict_message_order) {
        error(std::move(text));
      } else {
        warn(std::move(text));
      }
    }
    min_time = std::min(min_time, m.log_time);
    max_time = std::max(max_time, m.log_time);
    max_log_time_ = std::max(max_log_time_, m.log_time);
    ++count;
    ++message_count_;
    ++channel_message_counts_[m.channel_id];
    const auto idx = index_entries.find(m.channel_id);
    if (idx == index_entries.end()) {
      warn(cat(where, ": No MessageIndex record found for channel ", m.channel_id));
      continue;
    }
    const auto entry = idx->second.find(offset);
    if (entry == idx->second.end()) {
      warn(cat("No MessageIndex entry found for message channel ", m.channel_id, " with log time ",
               m.log_time, " at offset ", offset, " (", where, ")"));
    } else if (entry->second != m.log_time) {
      error(cat("MessageIndex entry for channel ", m.channel_id, " at offset ", offset, " has timestamp ",
                entry->second, ", but message has timestamp ", m.log_time, " (", where, ")"));
    }
  }
  // The other direction: every index entry names a message of its channel.
  for (const auto& [channel_id, entries] : index_entries) {
    std::vector<std::uint64_t> offsets;
    for (const auto& [offset, t] : entries) offsets.push_back(offset);
    std::sort(offsets.begin(), offsets.end());
    for (std::uint64_t offset : offsets) {
      const auto m = message_at.find(offset);
      if (m == message_at.end()) {
        error(cat("MessageIndex for channel ", channel_id, " (", where, ") has an entry at offset ", offset,
                  " where there is no Message record"));
      } else if (m->second != channel_id) {
        error(cat("MessageIndex for channel ", channel_id, " (", where, ") has an entry at offset ", offset,
                  " that points at a message of channel ", m->second));
      }
    }
  }
  if (count != 0) {
    if (min_time != chunk.message_start_time) {
      error(cat("Chunk.message_start_time ", chunk.message_start_time,
                " does not match the earliest message log time ", min_time, " (", where, ")"));
    }
    if (max_time != chunk.message_end_time) {
      error(cat("Chunk.message_end_time ", chunk.message_end_time,
                " does not match the latest message log time ", max_time, " (", where, ")"));
    }
    min_log_time_ = std::min(min_log_time_, min_time);
  }
}

void Doctor::check_footer_offsets() {
  const mcap::Footer& footer = *footer_;
  if (!data_end_) return;
  // Summary section: records between DataEnd and the summary offset section.
  std::uint64_t offsets_start = 0;  // first SummaryOffset record
  bool summary_records = false;
  for (const SummaryRecord& r : summary_records_) {
    if (r.opcode == op(mcap::Opcode::SummaryOffset)) {
      if (offsets_start == 0) offsets_start = r.offset;
    } else if (offsets_start != 0) {
      error(
          cat(opcode_name(r.opcode), " record at offset ", r.offset, " follows the summary offset section"));
    } else {
      summary_records = true;
    }
  }
  if (footer.summary_start != 0) {
    if (!summary_records) {
      error(cat("Footer.summary_start is ", footer.summary_start, ", but the file has no summary section"));
    } else if (footer.summary_start != summary_begin_) {
      error(cat("Footer.summary_start is ", footer.summary_start, ", but the summary section starts at ",
                summary_begin_));
    }
  } else if (summary_records) {
    warn(cat("the file has a summary section at offset ", summary_begin_,
             " but Footer.summary_start is 0: readers will not use it"));
  }
  if (footer.summary_offset_start != 0) {
    if (offsets_start == 0) {
      error(cat("Footer.summary_offset_start is ", footer.summary_offset_start,
                ", but the file has no SummaryOffset records"));
    } else if (footer.summary_offset_start != offsets_start) {
      error(cat("Footer.summary_offset_start is ", footer.summary_offset_start,
                ", but the summary offset section starts at ", offsets_start));
    }
  } else if (offsets_start != 0) {
    warn(cat("the file has SummaryOffset records at offset ", offsets_start,
             " but Footer.summary_offset_start is 0"));
  }
}

void Doctor::check_summary_offsets() {
  std::set<std::uint8_t> seen;
  for (const auto& [at, so] : summary_offsets_) {
    const std::string name = opcode_name(so.group_opcode);
    const std::string where = cat("SummaryOffset at offset ", at, " (", name, " group)");
    if (!seen.insert(so.group_opcode).second) {
      error(cat(where, ": a second summary offset for the same opcode"));
      continue;
    }
    auto it = std::find_if(summary_records_.begin(), summary_records_.end(),
                           [&](const SummaryRecord& r) { return r.offset == so.group_start; });
    if (it == summary_records_.end()) {
      error(cat(where, ": group_start ", so.group_start, " is not the start of a summary record"));
      continue;
    }
    std::uint64_t covered = 0, in_group = 0;
    bool bad = false;
    for (; it != summary_records_.end() && covered < so.group_length; ++it) {
      if (it->opcode != so.group_opcode) {
        error(cat(where, ": the group holds a ", opcode_name(it->opcode), " record at offset ", it->offset));
        bad = true;
        break;
      }
      covered += it->length;
      ++in_group;
    }
    if (bad) continue;
    if (covered != so.group_length) {
      error(cat(where, ": group_length ", so.group_length,
                " does not end at a record boundary (records cover ", covered, " bytes)"));
      continue;
    }
    const auto total = static_cast<std::uint64_t>(
        std::count_if(summary_records_.begin(), summary_records_.end(),
                      [&](const SummaryRecord& r) { return r.opcode == so.group_opcode; }));
    if (total != in_group) {
      error(cat(where, ": the group holds ", in_group, " of the ", total, " ", name,
                " records in the summary"));
    }
  }
}

void Doctor::check_chunk_indexes() {
  for (const auto& [offset, ci] : chunk_indexes_) {
    const std::string where = cat("Chunk index for offset ", offset);
    const auto found = chunks_.find(offset);
    if (found == chunks_.end()) {
      error(cat("Chunk index points to offset ", offset, ", where there is no Chunk record"));
      continue;
    }
    const ChunkInfo& chunk = found->second;
    for (std::uint16_t id : chunk.channels) {
      if (summary_channel_ids_.count(id) == 0) {
        error(cat("Indexed chunk at offset ", offset, " contains messages referencing channel (", id,
                  ") not duplicated in summary section"));
      }
      const auto channel = channels_.find(id);
      if (channel == channels_.end()) continue;  // reported where the message was read
      if (channel->second.schema_id != 0 && summary_schema_ids_.count(channel->second.schema_id) == 0) {
        error(cat("Indexed chunk at offset ", offset, " contains messages referencing schema (",
                  channel->second.schema_id, ") not duplicated in summary section"));
      }
    }
    if (ci.chunk_length != chunk.length) {
      error(cat("Chunk index ", offset, " length mismatch: ", ci.chunk_length, " vs ", chunk.length, "."));
      continue;
    }
    if (chunk.start != ci.message_start_time) {
      error(cat("Chunk at offset ", offset, " has message start time ", chunk.start,
                ", but its chunk index has message start time ", ci.message_start_time));
    }
    if (chunk.end != ci.message_end_time) {
      error(cat("Chunk at offset ", offset, " has message end time ", chunk.end,
                ", but its chunk index has message end time ", ci.message_end_time));
    }
    if (chunk.compression != ci.compression) {
      error(cat("Chunk at offset ", offset, " has compression \"", chunk.compression,
                "\", but its chunk index has compression \"", ci.compression, "\""));
    }
    if (chunk.compressed_size != ci.compressed_size) {
      error(cat("Chunk at offset ", offset, " has data length ", chunk.compressed_size,
                ", but its chunk index has compressed size ", ci.compressed_size));
    }
    if (chunk.uncompressed_size != ci.uncompressed_size) {
      error(cat("Chunk at offset ", offset, " has uncompressed size ", chunk.uncompressed_size,
                ", but its chunk index has uncompressed size ", ci.uncompressed_size));
    }
    for (const auto& [channel_id, index_offset] : ci.message_index_offsets) {
      const auto real = chunk.index_offsets.find(channel_id);
      if (real == chunk.index_offsets.end()) {
        error(cat(where, ": message index offset ", index_offset, " for channel ", channel_id,
                  ", but the chunk has no MessageIndex record for that channel"));
      } else if (real->second != index_offset) {
        error(cat(where, ": message index offset for channel ", channel_id, " is ", index_offset,
                  ", but its MessageIndex record is at offset ", real->second));
      }
    }
    for (const auto& [channel_id, index_offset] : chunk.index_offsets) {
      if (ci.message_index_offsets.count(channel_id) == 0) {
        error(cat(where, ": no message index offset for channel ", channel_id,
                  " (its MessageIndex record is at offset ", index_offset, ")"));
      }
    }
    if (!ci.message_index_offsets.empty() && ci.message_index_length != chunk.index_length) {
      error(cat(where, ": message_index_length is ", ci.message_index_length,
                ", but the chunk's MessageIndex records take ", chunk.index_length, " bytes"));
    }
  }
  if (!chunk_indexes_.empty()) {
    for (const auto& [offset, chunk] : chunks_) {
      if (chunk_indexes_.count(offset) == 0) {
        error(cat("Chunk at offset ", offset, " has no chunk index: indexed readers will miss its messages"));
      }
    }
  }
}

void Doctor::check_statistics() {
  if (!statistics_) return;
  const mcap::Statistics& s = *statistics_;
  if (message_count_ > 0) {
    if (s.message_start_time != min_log_time_) {
      error(cat("Statistics has message start time ", s.message_start_time,
                ", but the minimum message start time is ", min_log_time_));
    }
    if (s.message_end_time != max_log_time_) {
      error(cat("Statistics has message end time ", s.message_end_time,
                ", but the maximum message end time is ", max_log_time_));
    }
  }
  if (s.message_count != message_count_) {
    error(cat("Statistics has message count ", s.message_count, ", but actual number of messages is ",
              message_count_));
  }
  for (const auto& [channel_id, count] : channel_message_counts_) {
    const auto it = s.channel_message_counts.find(channel_id);
    const std::uint64_t stated = it == s.channel_message_counts.end() ? 0 : it->second;
    if (stated != count) {
      error(cat("Statistics has message count ", stated, " for channel ", channel_id,
                ", but actual number of messages is ", count));
    }
  }
  for (const auto& [channel_id, stated] : s.channel_message_counts) {
    if (stated != 0 && channel_message_counts_.count(channel_id) == 0) {
      error(cat("Statistics has message count ", stated, " for channel ", channel_id,
                ", but the channel has no messages"));
    }
  }
  auto count = [&](const char* what, std::uint64_t stated, std::uint64_t actual) {
    if (stated != actual)
      error(cat("Statistics has ", what, " count ", stated, ", but the file has ", actual));
  };
  count("schema", s.schema_count, schemas_.size());
  count("channel", s.channel_count, channels_.size());
  count("chunk", s.chunk_count, chunks_.size());
  count("attachment", s.attachment_count, attachments_.size());
  count("metadata", s.metadata_count, metadata_.size());
}

void Doctor::check_attachment_and_metadata_indexes() {
  std::set<std::uint64_t> indexed;
  for (const auto& [at, ai] : attachment_indexes_) {
    const std::string where = cat("AttachmentIndex at offset ", at);
    const auto it = attachments_.find(ai.offset);
    if (it == attachments_.end()) {
      error(cat(where, " points to offset ", ai.offset, ", where there is no Attachment record"));
      continue;
    }
    indexed.insert(ai.offset);
    const AttachmentSeen& a = it->second;
    if (ai.length != a.length)
      error(cat(where, ": length ", ai.length, ", but the Attachment record takes ", a.length));
    if (ai.log_time != a.log_time)
      error(cat(where, ": log_time ", ai.log_time, ", but the attachment has ", a.log_time));
    if (ai.create_time != a.create_time) {
      error(cat(where, ": create_time ", ai.create_time, ", but the attachment has ", a.create_time));
    }
    if (ai.data_size != a.data_size)
      error(cat(where, ": data_size ", ai.data_size, ", but the attachment has ", a.data_size));
    if (ai.name != a.name)
      error(cat(where, ": name \"", ai.name, "\", but the attachment is \"", a.name, "\""));
    if (ai.media_type != a.media_type) {
      error(
          cat(where, ": media_type \"", ai.media_type, "\", but the attachment has \"", a.media_type, "\""));
    }
  }
  if (!attachment_indexes_.empty()) {
    for (const auto& [offset, a] : attachments_) {
      if (indexed.count(offset) == 0)
        error(cat("Attachment \"", a.name, "\" at offset ", offset, " has no attachment index"));
    }
  }
  indexed.clear();
  for (const auto& [at, mi] : metadata_indexes_) {
    const std::string where = cat("MetadataIndex at offset ", at);
    const auto it = metadata_.find(mi.offset);
    if (it == metadata_.end()) {
      error(cat(where, " points to offset ", mi.offset, ", where there is no Metadata record"));
      continue;
    }
    indexed.insert(mi.offset);
    if (mi.length != it->second.first) {
      error(cat(where, ": length ", mi.length, ", but the Metadata record takes ", it->second.first));
    }
    if (mi.name != it->second.second) {
      error(cat(where, ": name \"", mi.name, "\", but the metadata is \"", it->second.second, "\""));
    }
  }
  if (!metadata_indexes_.empty()) {
    for (const auto& [offset, m] : metadata_) {
      if (indexed.count(offset) == 0)
        error(cat("Metadata \"", m.second, "\" at offset ", offset, " has no metadata index"));
    }
  }
}

}  // namespace

DoctorReport doctor(const std::string& path, const DoctorOptions& options) {
  return Doctor(options).run(path);
}

}  // namespace rbsim::mcap_tools
