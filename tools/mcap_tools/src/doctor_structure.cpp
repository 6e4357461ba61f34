// rbsim log doctor, the structure walk: magic, record framing, record order, the data section and
// summary CRCs, the Footer and what follows it. Each record is handed to its handler
// (doctor_records.cpp) as it is read.
#include "doctor.hpp"

namespace rbsim::mcap_tools::detail {

using mcap::opcode_name;
using mcap::opcode_of;
using mcap::RecordReader;

bool Doctor::walk(mcap::ByteSource& source) {
  if (size_ == 0) {
    error("empty file (0 bytes): not an MCAP file");
    return false;
  }
  if (!check_leading_magic(source)) return false;
  std::uint8_t last_opcode = 0;
  RecordReader reader(source, mcap::kMagicSize);
  reader.on_problem([&](const mcap::RecordProblem& p) { report_unframed(p, last_opcode); });
  mcap::RecordView record;
  for (bool first = true; reader.next(record); first = false) {
    pos_ = record.offset;
    last_opcode = record.opcode;
    const Step step = walk_record(source, record, first);
    if (step == Step::kStop) return false;
    if (step == Step::kEnd) break;
  }
  if (!reader.status().ok()) return false;
  flush_chunk();
  return check_footer_and_crcs(last_opcode);
}

bool Doctor::check_leading_magic(mcap::ByteSource& source) {
  const Status magic = mcap::check_magic(source, 0);
  if (magic.code() == ErrorCode::BadMagic || magic.code() == ErrorCode::Truncated) {
    error(mcap::describe_read_error(magic.error()));
    return false;
  }
  // The data section CRC covers the leading magic too.
  mcap::ByteView head;
  if (!magic.ok() || !source.read(0, mcap::kMagicSize, head).ok()) {
    error("cannot read the file");
    return false;
  }
  data_crc_ = mcap::crc32(head);
  return true;
}

void Doctor::report_unframed(const mcap::RecordProblem& p, std::uint8_t last_opcode) {
  if (p.status.code() == ErrorCode::IoError) {
    error(p.content_length ? cat("cannot read ", *p.content_length, " bytes at offset ",
                                 p.offset + RecordReader::kPrefixSize)
                           : cat("cannot read at offset ", p.offset));
    return;
  }
  flush_chunk();
  if (!p.content_length) {
    error(cat("truncated: the file ends inside a record header at offset ", p.offset, " (", p.available,
              " bytes left, last record was ", opcode_name(last_opcode), ")"));
  } else {
    error(cat("truncated: ", opcode_name(*p.opcode), " record at offset ", p.offset, " claims ",
              *p.content_length, " bytes, but only ", p.available - RecordReader::kPrefixSize, " remain"));
  }
}

Doctor::Step Doctor::walk_record(mcap::ByteSource& source, const mcap::RecordView& record, bool first) {
  const std::uint8_t opcode = record.opcode;
  const bool is_footer = opcode == opcode_of<mcap::Footer>();
  const bool is_data_end = opcode == opcode_of<mcap::DataEnd>();
  if (!data_end_ && !is_data_end) {
    data_crc_ = mcap::crc32(record.content, mcap::crc32(record.prefix_bytes(), data_crc_));
  } else if (data_end_ && !is_footer) {
    summary_crc_ = mcap::crc32(record.content, mcap::crc32(record.prefix_bytes(), summary_crc_));
  }
  if (opcode != opcode_of<mcap::MessageIndex>()) flush_chunk();
  if (first && opcode != opcode_of<mcap::Header>()) {
    error(cat("the first record is a ", opcode_name(opcode), ", not a Header"));
  }
  if (opcode == 0) {
    // Typically the zero-filled tail of a file whose writer died: nothing after it is a record.
    flush_chunk();
    error(cat("invalid record (opcode 0x00) at offset ", pos_,
              ": the rest of the file is not MCAP records (zero-filled?)"));
    return Step::kStop;
  }
  if (!mcap::is_known_opcode(opcode) && !mcap::is_private_opcode(opcode)) {
    warn(cat("unknown record opcode 0x", std::hex, static_cast<int>(opcode), std::dec, " at offset ", pos_,
             " (ignored)"));
  } else if (mcap::is_known_opcode(opcode)) {
    auto parsed = mcap::parse_record(opcode, record.content);
    if (!parsed.ok()) {
      error(cat("failed to parse ", opcode_name(opcode), " record at offset ", pos_, ": ",
                parsed.error().message));
    } else {
      handle(record, parsed.value());
    }
  }
  if (data_end_ && !is_footer && !is_data_end) summary_records_.push_back({opcode, pos_, record.length});
  return is_footer ? check_file_end(source, record) : Step::kNext;
}

// The Footer's part of the summary CRC, and the trailing magic after it.
Doctor::Step Doctor::check_file_end(mcap::ByteSource& source, const mcap::RecordView& footer) {
  // The summary CRC covers the Footer up to its own summary_crc field (summary_start and
  // summary_offset_start: 16 bytes).
  constexpr std::size_t kCoveredFooter = 16;
  if (footer.content.size() >= kCoveredFooter) {
    summary_crc_ = mcap::crc32(footer.content.subspan(0, kCoveredFooter),
                               mcap::crc32(footer.prefix_bytes(), summary_crc_));
  }
  const std::uint64_t after = footer.offset + footer.length;
  if (size_ - after < mcap::kMagicSize) {
    error(cat("truncated: the file ends ", size_ - after, " bytes into the trailing magic"));
    return Step::kStop;
  }
  if (!mcap::check_magic(source, after).ok())
    error(cat("the trailing magic bytes at offset ", after, " are wrong"));
  if (size_ - after > mcap::kMagicSize) {
    error(cat(size_ - after - mcap::kMagicSize, " unexpected bytes after the trailing magic"));
  }
  return Step::kEnd;
}

bool Doctor::check_footer_and_crcs(std::uint8_t last_opcode) {
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

}  // namespace rbsim::mcap_tools::detail
