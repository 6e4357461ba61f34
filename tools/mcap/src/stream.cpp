#include "stream.hpp"

#include <array>
#include <cstring>

#include "wire.hpp"

namespace rbsim::mcap {
namespace detail {
namespace {

constexpr std::uint8_t op(Opcode o) {
  return static_cast<std::uint8_t>(o);
}

}  // namespace

Status check_attachment_crc(ByteView content, const Attachment& a) {
  if (a.crc == 0) return Ok{};
  const std::size_t covered = 8 + 8 + 4 + a.name.size() + 4 + a.media_type.size() + 8 + a.data.size();
  const std::uint32_t crc = crc32(content.subspan(0, covered));
  if (crc == a.crc) return Ok{};
  return Error{
      "attachment '" + a.name + "' CRC mismatch: computed " + crc_text(crc) + ", stored " + crc_text(a.crc),
      ErrorCode::CrcMismatch};
}

bool Streamer::fail(Status status) {
  status_ = std::move(status);
  state_ = State::Done;
  in_chunk_ = false;
  return false;
}

bool Streamer::next(RecordEntry& out) {
  while (state_ != State::Done) {
    if (in_chunk_) {
      if (!chunk_error_.ok()) return fail(std::move(chunk_error_));
      if (!chunk_records_.at_end()) return next_in_chunk(out);
      in_chunk_ = false;
    }
    bool yield = false;
    if (!read_top_level(out, yield)) return false;
    if (yield) return true;
  }
  return false;
}

bool Streamer::next_in_chunk(RecordEntry& out) {
  RecordView rec;
  if (!chunk_records_.next(rec)) {
    return fail(Error{"record cut off at byte " + std::to_string(chunk_records_.position()) +
                          " of the chunk" + at(chunk_offset_),
                      ErrorCode::Malformed});
  }
  if (rec.opcode == op(Opcode::Message)) {
    // Into the caller's Message, reusing its buffer: a fresh one per message is fresh pages.
    Message* message = std::get_if<Message>(&out.record);
    if (message == nullptr) message = &out.record.emplace<Message>();
    if (Status s = parse_message_into(rec.content, *message); !s.ok()) {
      return fail(Error{s.error().message + " in chunk" + at(chunk_offset_), s.error().code});
    }
  } else {
    auto record = parse_record(rec.opcode, rec.content);
    if (!record.ok()) {
      return fail(Error{record.error().message + " in chunk" + at(chunk_offset_), record.error().code});
    }
    out.record = std::move(record).value();
  }
  out.offset = rec.offset;
  out.length = rec.length;
  out.chunk_offset = chunk_offset_;
  return true;
}

void Streamer::update_crcs(const RecordView& record) {
  if (!options_.verify_crcs) return;
  if (!seen_data_end_) {
    data_crc_ = crc32(record.content, crc32(record.prefix_bytes(), data_crc_));
  } else if (record.opcode != op(Opcode::Footer)) {
    summary_crc_ = crc32(record.content, crc32(record.prefix_bytes(), summary_crc_));
  }
}

// The leading magic; the records follow it.
bool Streamer::start() {
  if (source_.size() == 0) return fail(Error{"empty file", ErrorCode::Truncated});
  if (Status s = check_magic(source_, 0); !s.ok()) return fail(s);  // worded by describe_read_error
  if (options_.verify_crcs) data_crc_ = crc32(ByteView(kMagic, sizeof kMagic));
  position_ = sizeof kMagic;
  records_.reset(position_);
  state_ = State::Records;
  return true;
}

// The summary CRC, then the trailing magic and nothing after it.
bool Streamer::check_footer(const RecordView& footer_record, const Footer& footer) {
  // Spec: "The last record in the data section MUST be the Data End record".
  if (!seen_data_end_) return fail(Error{"Footer without a DataEnd record", ErrorCode::Malformed});
  // The summary CRC runs from the end of DataEnd through Footer.summary_offset_start.
  const std::uint32_t stored = footer.summary_crc;
  const std::uint32_t computed =
      crc32(footer_record.content.subspan(0, 16), crc32(footer_record.prefix_bytes(), summary_crc_));
  if (options_.verify_crcs && stored != 0 && stored != computed) {
    return fail(Error{
        "summary CRC mismatch: computed " + std::to_string(computed) + ", stored " + std::to_string(stored),
        ErrorCode::CrcMismatch});
  }
  const std::uint64_t size = source_.size();
  if (size - position_ < sizeof kMagic) {
    return fail(Error{"file ends inside the trailing magic", ErrorCode::Truncated});
  }
  if (Status s = check_magic(source_, position_); !s.ok()) {
    if (s.code() != ErrorCode::BadMagic) return fail(s);
    return fail(Error{"bad trailing magic" + at(position_), ErrorCode::BadMagic});
  }
  if (size - position_ > sizeof kMagic) {
    return fail(Error{"unexpected bytes after the trailing magic", ErrorCode::Malformed});
  }
  position_ = size;
  state_ = State::Done;
  return true;
}

bool Streamer::read_top_level(RecordEntry& out, bool& yield) {
  if (state_ == State::Start && !start()) return false;
  RecordView rec;
  if (!records_.next(rec)) {
    if (!records_.status().ok()) return fail(records_.status());
    return fail(Error{"file ends without a Footer", ErrorCode::Truncated});
  }
  const std::uint8_t opcode = rec.opcode;
  const ByteView content = rec.content;
  if (first_record_ && opcode != op(Opcode::Header)) {
    return fail(Error{"first record is not a Header" + at(position_), ErrorCode::Malformed});
  }
  first_record_ = false;
  const bool is_data_end = opcode == op(Opcode::DataEnd);
  const std::uint32_t data_crc = data_crc_;
  if (!is_data_end) update_crcs(rec);

  // A Chunk that is only descended into is decompressed straight from the file buffer.
  const bool chunk_view =
      opcode == op(Opcode::Chunk) && options_.descend_into_chunks && !options_.report_chunks;
  ByteView chunk_records;
  Result<Record> parsed = Record{};
  if (chunk_view) {
    Chunk chunk;
    if (Status s = parse_chunk_view(content, chunk, chunk_records); !s.ok()) {
      return fail(Error{s.error().message + at(position_), s.error().code});
    }
    parsed = Record(std::move(chunk));
  } else {
    parsed = parse_record(opcode, content);
  }
  if (!parsed.ok()) return fail(Error{parsed.error().message + at(position_), parsed.error().code});
  Record& record = parsed.value();
  const std::uint64_t record_offset = position_;
  out.offset = record_offset;
  out.length = rec.length;
  out.chunk_offset.reset();
  position_ = records_.position();
  yield = true;

  switch (static_cast<Opcode>(opcode)) {
    case Opcode::DataEnd: {
      const std::uint32_t stored = std::get<DataEnd>(record).data_section_crc;
      if (options_.verify_crcs && stored != 0 && stored != data_crc) {
        return fail(Error{"data section CRC mismatch: computed " + crc_text(data_crc) + ", stored " +
                              std::to_string(stored),
                          ErrorCode::CrcMismatch});
      }
      seen_data_end_ = true;
      break;
    }
    case Opcode::Chunk:
      if (options_.descend_into_chunks) {
        const Chunk& chunk = std::get<Chunk>(record);
        chunk_error_ = decompressor_.decompress(chunk, chunk_view ? chunk_records : ByteView(chunk.records),
                                                chunk_data_, options_.verify_crcs);
        if (!chunk_error_.ok()) {
          chunk_error_ = Error{chunk_error_.error().message + " (chunk" + at(record_offset) + ")",
                               chunk_error_.error().code};
        }
        chunk_source_.reset(chunk_data_);
        chunk_records_.reset(0);
        chunk_offset_ = record_offset;
        in_chunk_ = true;
      }
      yield = options_.report_chunks || !options_.descend_into_chunks;
      break;
    case Opcode::MessageIndex:
      yield = options_.report_message_indexes;
      break;
    case Opcode::Attachment:
      if (options_.verify_crcs) {
        if (Status s = check_attachment_crc(content, std::get<Attachment>(record)); !s.ok()) return fail(s);
      }
      break;
    case Opcode::Footer:
      if (!check_footer(rec, std::get<Footer>(record))) return false;
      break;
    default:
      break;
  }
  if (yield) out.record = std::move(record);
  return true;
}

}  // namespace detail

struct StreamReader::Impl {
  std::unique_ptr<ByteSource> source;
  std::unique_ptr<detail::Streamer> streamer;
  Status not_open = Error{"stream reader is not open", ErrorCode::NotOpen};

  Status start(std::unique_ptr<ByteSource> s, const StreamOptions& options) {
    source = std::move(s);
    streamer = std::make_unique<detail::Streamer>(*source, options);
    return Ok{};
  }
};

StreamReader::StreamReader() : impl_(std::make_unique<Impl>()) {}
StreamReader::~StreamReader() = default;

Status StreamReader::open(const std::string& path, const StreamOptions& options) {
  auto source = open_file_source(path);
  if (!source.ok()) return source.error();
  return impl_->start(std::move(source).value(), options);
}

Status StreamReader::open_buffer(Bytes data, const StreamOptions& options) {
  return impl_->start(make_buffer_source(std::move(data)), options);
}

bool StreamReader::next(RecordEntry& out) {
  return impl_->streamer && impl_->streamer->next(out);
}
const Status& StreamReader::status() const {
  return impl_->streamer ? impl_->streamer->status() : impl_->not_open;
}
std::uint64_t StreamReader::position() const {
  return impl_->streamer ? impl_->streamer->position() : 0;
}

}  // namespace rbsim::mcap
