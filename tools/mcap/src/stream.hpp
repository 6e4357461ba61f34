// Linear record walk shared by StreamReader and the IndexedReader's fallback scan.
#pragma once

#include "byte_sink.hpp"
#include "codec.hpp"
#include "rbsim/mcap_records.hpp"

namespace rbsim::mcap::detail {

// Checks Attachment.crc (when non-zero) against the content bytes it covers.
Status check_attachment_crc(ByteView content, const Attachment& attachment);

class Streamer {
 public:
  Streamer(ByteSource& source, const StreamOptions& options)
      : source_(source), options_(options), records_(source), chunk_records_(chunk_source_) {}

  bool next(RecordEntry& out);
  const Status& status() const { return status_; }
  std::uint64_t position() const { return position_; }

 private:
  enum class State { Start, Records, Done };

  bool fail(Status status);
  bool next_in_chunk(RecordEntry& out);
  bool read_top_level(RecordEntry& out, bool& yield);
  bool start();
  bool check_footer(const RecordView& footer_record, const Footer& footer);
  void update_crcs(const RecordView& record);

  ByteSource& source_;
  StreamOptions options_;
  Status status_;
  State state_ = State::Start;
  RecordReader records_;  // the top-level records, after the leading magic
  std::uint64_t position_ = 0;
  bool first_record_ = true;
  bool seen_data_end_ = false;
  std::uint32_t data_crc_ = 0;
  std::uint32_t summary_crc_ = 0;

  bool in_chunk_ = false;
  Status chunk_error_;  // decompression failure, reported after the Chunk record itself
  Bytes chunk_data_;
  Decompressor decompressor_;
  ViewSource chunk_source_;     // views chunk_data_
  RecordReader chunk_records_;  // the records of the chunk being reported
  std::uint64_t chunk_offset_ = 0;
};

}  // namespace rbsim::mcap::detail
