// rbsim log doctor's stages and the state they share (private to mcap_tools). Doctor::run calls
// them in order, each in its own file: the structure walk (doctor_structure.cpp, one pass over
// the file record by record, each record to its handler in doctor_records.cpp), the chunk
// examination (doctor_chunks.cpp, as each chunk's message indexes end), then the summary and
// index checks (doctor_summary.cpp) and the statistics (doctor_statistics.cpp) over what the walk
// collected.
#pragma once

#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "rbsim/mcap_records.hpp"
#include "rbsim/mcap_tools.hpp"

namespace rbsim::mcap_tools::detail {

template <class... A>
std::string cat(const A&... a) {
  std::ostringstream s;
  (s << ... << a);
  return s.str();
}

inline std::string hex32(std::uint32_t v) {
  return mcap::crc_text(v);
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

struct ChunkScan;  // one chunk's records against its message indexes (doctor_chunks.cpp)

class Doctor {
 public:
  explicit Doctor(const DoctorOptions& options) : options_(options) {}
  DoctorReport run(const std::string& path);

 private:
  static constexpr std::size_t kMaxFindings = 1000;  // further findings are counted, not stored
  enum class Step { kNext, kStop, kEnd };            // after a record: read on, give up, Footer read

  void add(bool is_error, std::string text) {
    (is_error ? report_.errors : report_.warnings)++;
    if (report_.findings.size() < kMaxFindings) report_.findings.push_back({is_error, std::move(text)});
  }
  void error(std::string text) { add(true, std::move(text)); }
  void warn(std::string text) { add(false, std::move(text)); }

  // The structure walk (doctor_structure.cpp). False when the file could not be read to its
  // Footer (the summary checks then make no sense); the reason is already reported.
  bool walk(mcap::ByteSource& source);
  bool check_leading_magic(mcap::ByteSource& source);
  void report_unframed(const mcap::RecordProblem& problem, std::uint8_t last_opcode);
  Step walk_record(mcap::ByteSource& source, const mcap::RecordView& record, bool first);
  Step check_file_end(mcap::ByteSource& source, const mcap::RecordView& footer);
  bool check_footer_and_crcs(std::uint8_t last_opcode);

  // One parsed record of the walk, by type (doctor_records.cpp).
  void handle(const mcap::RecordView& view, mcap::Record& record);
  void on(const mcap::RecordView& view, const mcap::Header& header);
  void on(const mcap::RecordView& view, const mcap::Footer& footer);
  void on(const mcap::RecordView& view, const mcap::Schema& schema);
  void on(const mcap::RecordView& view, const mcap::Channel& channel);
  void on(const mcap::RecordView& view, const mcap::Message& message);
  void on(const mcap::RecordView& view, mcap::Chunk& chunk);
  void on(const mcap::RecordView& view, mcap::MessageIndex& index);
  void on(const mcap::RecordView& view, mcap::ChunkIndex& index);
  void on(const mcap::RecordView& view, const mcap::Attachment& attachment);
  void on(const mcap::RecordView& view, const mcap::AttachmentIndex& index);
  void on(const mcap::RecordView& view, const mcap::Statistics& statistics);
  void on(const mcap::RecordView& view, const mcap::Metadata& metadata);
  void on(const mcap::RecordView& view, const mcap::MetadataIndex& index);
  void on(const mcap::RecordView& view, const mcap::SummaryOffset& offset);
  void on(const mcap::RecordView& view, const mcap::DataEnd& data_end);
  void on(const mcap::RecordView&, const mcap::UnknownRecord&) {}
  void data_only(const mcap::RecordView& view);
  void summary_only(const mcap::RecordView& view);
  void warn_messages_outside_chunks();
  void examine_schema(const mcap::Schema& schema);
  void examine_channel(const mcap::Channel& channel);

  // The chunk examination (doctor_chunks.cpp): once a chunk's MessageIndex records are read.
  void examine_chunk(PendingChunk& p);
  bool decompress(const mcap::Chunk& chunk, const std::string& where, mcap::Bytes& data);
  void examine_chunk_message(ChunkScan& scan, std::uint64_t offset, const mcap::Message& m);
  void check_index_entries(const ChunkScan& scan);
  void flush_chunk() {
    if (pending_) {
      examine_chunk(*pending_);
      pending_.reset();
    }
  }

  // The summary and index checks (doctor_summary.cpp) and the statistics (doctor_statistics.cpp).
  void check_footer_offsets();
  void check_summary_offsets();
  void check_chunk_indexes();
  void check_chunk_index(const mcap::ChunkIndex& ci, const ChunkInfo& chunk);
  void check_statistics();
  void check_attachment_indexes();
  void check_metadata_indexes();

  std::string topic_of(std::uint16_t channel_id) const {
    auto it = channels_.find(channel_id);
    return it == channels_.end() ? std::string("<unknown channel>") : it->second.topic;
  }
  std::string at_pos() const { return cat(" at offset ", pos_); }

  DoctorOptions options_;
  DoctorReport report_;
  std::uint64_t size_ = 0;
  std::uint64_t pos_ = 0;  // offset of the record being handled

  bool in_summary_ = false;
  bool seen_header_ = false;
  std::optional<mcap::DataEnd> data_end_;
  std::uint64_t summary_begin_ = 0;
  std::optional<mcap::Footer> footer_;
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

}  // namespace rbsim::mcap_tools::detail
