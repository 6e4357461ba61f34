// Linear record walk shared by StreamReader and the IndexedReader's fallback scan.
#pragma once

#include "codec.hpp"
#include "io.hpp"

namespace rbsim::mcap::detail {

// Reads <opcode><length><content> at `offset`, bounding `length` by the bytes left in the source.
Status read_record_at(Source& source, std::uint64_t offset, std::uint8_t& opcode, ByteView& content);
// Checks Attachment.crc (when non-zero) against the content bytes it covers.
Status check_attachment_crc(ByteView content, const Attachment& attachment);

class Streamer {
 public:
  Streamer(Source& source, const StreamOptions& options) : source_(source), options_(options) {}

  bool next(RecordEntry& out);
  const Status& status() const { return status_; }
  std::uint64_t position() const { return position_; }

 private:
  enum class State { Start, Records, Done };

  bool fail(Status status);
  bool next_in_chunk(RecordEntry& out);
  bool read_top_level(RecordEntry& out, bool& yield);
  void update_crcs(std::uint8_t opcode, ByteView prefix, ByteView content);

  Source& source_;
  StreamOptions options_;
  Status status_;
  State state_ = State::Start;
  std::uint64_t position_ = 0;
  bool first_record_ = true;
  bool seen_data_end_ = false;
  std::uint32_t data_crc_ = 0;
  std::uint32_t summary_crc_ = 0;

  bool in_chunk_ = false;
  Status chunk_error_;  // decompression failure, reported after the Chunk record itself
  Bytes chunk_data_;
  Decompressor decompressor_;
  std::size_t chunk_pos_ = 0;
  std::uint64_t chunk_offset_ = 0;
};

}  // namespace rbsim::mcap::detail
