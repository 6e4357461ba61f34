// Record framing (spec: Records): the one place that reads opcodes, length prefixes and magic.
#include <cstring>
#include <string>

#include "rbsim/mcap_records.hpp"
#include "wire.hpp"

namespace rbsim::mcap {

using detail::at;

Status check_magic(ByteSource& source, std::uint64_t offset) {
  const std::uint64_t size = source.size();
  const std::uint64_t n = offset > size ? 0 : std::min<std::uint64_t>(size - offset, sizeof kMagic);
  ByteView view;
  if (n > 0) {
    if (Status s = source.read(offset, n, view); !s.ok()) return s;
    if (std::memcmp(view.data(), kMagic, view.size()) != 0) {
      if (offset == 0) return Error{"the leading magic bytes are wrong", ErrorCode::BadMagic};
      return Error{"bad magic" + at(offset), ErrorCode::BadMagic};
    }
  }
  if (n < sizeof kMagic) {
    if (offset == 0) {
      return Error{"the file ends inside the leading magic (" + std::to_string(size) + " bytes)",
                   ErrorCode::Truncated};
    }
    return Error{"file ends inside the magic" + at(offset), ErrorCode::Truncated};
  }
  return Ok{};
}

std::string describe_read_error(const Error& error) {
  switch (error.code) {
    case ErrorCode::BadMagic:
      return "not an MCAP file: " + error.message;
    case ErrorCode::Truncated:
      return "truncated: " + error.message;
    case ErrorCode::CrcMismatch:
    case ErrorCode::DecompressionFailed:
    case ErrorCode::Malformed:
      return "corrupted: " + error.message;
    default:
      return error.message;
  }
}

void RecordReader::reset(std::uint64_t begin, std::uint64_t end) {
  const std::uint64_t size = source_->size();
  end_ = std::min(end, size);
  position_ = begin;
  problem_ = RecordProblem{};
}

void RecordReader::seek(std::uint64_t offset) {
  position_ = offset;
  problem_ = RecordProblem{};
}

bool RecordReader::fail(RecordProblem problem) {
  problem_ = std::move(problem);
  if (on_problem_) on_problem_(problem_);
  return false;
}

bool RecordReader::next(RecordView& out) {
  if (!problem_.status.ok() || position_ >= end_) return false;
  const std::uint64_t offset = position_;
  const std::uint64_t available = end_ - offset;
  RecordProblem problem{offset, available, std::nullopt, std::nullopt, Ok{}};
  ByteView prefix;
  if (available < kPrefixSize) {
    if (Status s = source_->read(offset, available, prefix); !s.ok())
      return fail({offset, available, {}, {}, s});
    problem.opcode = std::to_integer<std::uint8_t>(prefix[0]);
    problem.status = Error{"record header cut off" + at(offset), ErrorCode::Truncated};
    return fail(std::move(problem));
  }
  if (Status s = source_->read(offset, kPrefixSize, prefix); !s.ok())
    return fail({offset, available, {}, {}, s});
  std::memcpy(out.prefix, prefix.data(), kPrefixSize);
  const auto opcode = std::to_integer<std::uint8_t>(prefix[0]);
  std::uint64_t length = 0;
  detail::Cursor(prefix.subspan(1)).u64(length);  // the prefix holds all 8 bytes: cannot fail
  problem.opcode = opcode;
  problem.content_length = length;
  if (length > available - kPrefixSize) {
    problem.status = Error{"record (opcode " + std::to_string(opcode) + ")" + at(offset) + " claims " +
                               std::to_string(length) + " bytes, only " +
                               std::to_string(available - kPrefixSize) + " remain",
                           ErrorCode::Truncated};
    return fail(std::move(problem));
  }
  if (Status s = source_->read(offset + kPrefixSize, length, out.content); !s.ok()) {
    problem.status = std::move(s);
    return fail(std::move(problem));
  }
  out.opcode = opcode;
  out.offset = offset;
  out.length = kPrefixSize + length;
  position_ = offset + out.length;
  return true;
}

Status read_record(ByteSource& source, std::uint64_t offset, RecordView& out) {
  RecordReader reader(source, offset);
  if (reader.next(out)) return Ok{};
  if (!reader.status().ok()) return reader.status();
  // An offset at (or past) the end: no bytes of a header at all.
  return Error{"record header cut off" + at(offset), ErrorCode::Truncated};
}

std::uint64_t footer_offset(std::uint64_t size) {
  return size - sizeof kMagic - detail::kFooterRecord;
}

Result<Footer> read_footer(ByteSource& source) {
  const std::uint64_t size = source.size();
  const std::uint64_t min_size =
      sizeof kMagic + detail::kRecordPrefix + detail::kFooterRecord + sizeof kMagic;
  if (size < min_size) return Error{"file too short for a Footer", ErrorCode::Truncated};
  if (Status s = check_magic(source, size - sizeof kMagic); !s.ok()) {
    if (s.code() == ErrorCode::IoError) return s.error();
    return Error{"no trailing magic: file truncated or never closed", ErrorCode::Truncated};
  }
  RecordView record;
  if (Status s = read_record(source, footer_offset(size), record); !s.ok()) return s.error();
  if (record.opcode != static_cast<std::uint8_t>(Opcode::Footer) ||
      record.content.size() != detail::kFooterContent) {
    return Error{"no Footer before the trailing magic", ErrorCode::Malformed};
  }
  auto parsed = parse_record(record.opcode, record.content);
  if (!parsed.ok()) return parsed.error();
  return std::get<Footer>(std::move(parsed).value());
}

}  // namespace rbsim::mcap
