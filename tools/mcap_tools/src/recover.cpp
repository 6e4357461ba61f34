// rbsim log recover: every complete record of a damaged file copied into a fresh, indexed one.
//
// The input is streamed record by record (mcap::StreamReader, which stops at the first record it
// cannot frame: the end of a truncated file). Chunks are the unit of recovery: each complete
// chunk is decompressed and CRC-checked here, so one corrupt chunk is skipped and the chunks after
// it are still kept; a chunk cut off by the end of the file is lost with its messages.

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <optional>

#include "rbsim/atomic_file.hpp"
#include "rbsim/mcap_tools.hpp"
#include "tools_util.hpp"

namespace rbsim::mcap_tools {

namespace {

namespace fs = std::filesystem;

bool same_file(const std::string& a, const std::string& b) {
  std::error_code ec;
  if (fs::exists(b, ec) && fs::equivalent(a, b, ec)) return true;
  const fs::path ca = fs::weakly_canonical(a, ec);
  if (ec) return false;
  const fs::path cb = fs::weakly_canonical(b, ec);
  return !ec && ca == cb;
}

// Whether the file ends in a Footer that points at a summary (checked before opening an
// IndexedReader, which would scan a whole file without one).
bool has_summary(mcap::ByteSource& file) {
  const auto footer = mcap::read_footer(file);
  return footer.ok() && footer.value().summary_start != 0;
}

// The record the input ends in, as far as the bytes at `offset` tell: its opcode and, when its
// prefix is whole, the content length it claims. Nothing when no byte is left (or readable).
struct CutRecord {
  std::uint8_t opcode = 0;
  std::optional<std::uint64_t> content_length;
};
std::optional<CutRecord> record_at(mcap::ByteSource& file, std::uint64_t offset) {
  mcap::RecordReader reader(file, offset);
  mcap::RecordView record;
  if (reader.next(record)) return CutRecord{record.opcode, record.content.size()};
  const mcap::RecordProblem& problem = reader.problem();
  if (!problem.opcode) return std::nullopt;
  return CutRecord{*problem.opcode, problem.content_length};
}

// Whether `byte` could start the trailing magic (whose cut-off the read status already words).
bool starts_magic(std::uint8_t byte) {
  const std::byte first_byte{byte};
  mcap::ViewSource first(mcap::ByteView(&first_byte, 1));
  return mcap::check_magic(first, 0).code() != ErrorCode::BadMagic;
}

class Recoverer {
 public:
  explicit Recoverer(RecoverReport& report) : report_(report) {}

  // Copies one data-section record; errors only for output failures.
  Status copy(mcap::Record& record) {
    if (auto* m = std::get_if<mcap::Message>(&record)) return message(*m);
    if (auto* s = std::get_if<mcap::Schema>(&record)) {
      Status st = writer_.add_schema(*s);
      if (st.code() == ErrorCode::InvalidArgument) {
        note("schema " + std::to_string(s->id) + " skipped: " + st.error().message);
        return Ok{};
      }
      if (st.ok() && schema_ids_.insert(s->id)) ++report_.schemas;
      return st;
    }
    if (auto* c = std::get_if<mcap::Channel>(&record)) {
      Status st = writer_.add_channel(*c);
      if (st.code() == ErrorCode::InvalidArgument) {
        note("channel " + std::to_string(c->id) + " (" + c->topic + ") skipped: " + st.error().message);
        return Ok{};
      }
      if (st.ok() && channel_ids_.insert(c->id)) ++report_.channels;
      return st;
    }
    if (auto* a = std::get_if<mcap::Attachment>(&record)) {
      Status st = writer_.add_attachment(a->log_time, a->create_time, a->name, a->media_type, a->data);
      if (st.ok()) ++report_.attachments;
      return st;
    }
    if (auto* md = std::get_if<mcap::Metadata>(&record)) {
      Status st = writer_.add_metadata(md->name, md->metadata);
      if (st.ok()) ++report_.metadata;
      return st;
    }
    return Ok{};
  }

  Status chunk(const mcap::Chunk& chunk, std::uint64_t offset) {
    mcap::Bytes data;
    if (Status s = mcap::decompress_chunk(chunk, data, true); !s.ok()) {
      ++report_.corrupt_chunks;
      note("chunk at offset " + std::to_string(offset) + " skipped: " + s.error().message);
      return Ok{};
    }
    mcap::ViewSource records(data);
    mcap::RecordReader reader(records);
    reader.on_problem([&](const mcap::RecordProblem& problem) {
      note("chunk at offset " + std::to_string(offset) + ": records cut off at byte " +
           std::to_string(problem.offset));
    });
    for (mcap::RecordView view; reader.next(view);) {
      auto record = mcap::parse_record(view.opcode, view.content);
      if (!record.ok()) {
        note("chunk at offset " + std::to_string(offset) +
             ": unreadable record skipped: " + record.error().message);
        continue;
      }
      if (Status s = copy(record.value()); !s.ok()) return s;
    }
    ++report_.chunks;
    return Ok{};
  }

  struct IdSet {
    std::vector<bool> seen = std::vector<bool>(65536, false);
    bool insert(std::uint16_t id) {
      if (seen[id]) return false;
      seen[id] = true;
      return true;
    }
  };

  mcap::Writer& writer() { return writer_; }

  // Schemas and channels of the input's summary, for channels whose own record was lost with a
  // corrupt chunk (rbsim logs define them in the first chunk and repeat them in the summary).
  void set_fallback(std::map<std::uint16_t, mcap::Schema> schemas,
                    std::map<std::uint16_t, mcap::Channel> channels) {
    fallback_schemas_ = std::move(schemas);
    fallback_channels_ = std::move(channels);
  }

 private:
  Status restore_channel(std::uint16_t id) {
    const auto c = fallback_channels_.find(id);
    if (c == fallback_channels_.end()) return Ok{};
    const std::uint16_t schema_id = c->second.schema_id;
    if (schema_id != 0 && !schema_ids_.seen[schema_id]) {
      const auto s = fallback_schemas_.find(schema_id);
      if (s == fallback_schemas_.end()) return Ok{};
      mcap::Record r = s->second;
      if (Status st = copy(r); !st.ok()) return st;
    }
    mcap::Record r = c->second;
    if (Status st = copy(r); !st.ok()) return st;
    if (channel_ids_.seen[id])
      note("channel " + std::to_string(id) + " (" + c->second.topic + ") restored from the summary section");
    return Ok{};
  }

  Status message(const mcap::Message& m) {
    if (!channel_ids_.seen[m.channel_id]) {
      if (Status st = restore_channel(m.channel_id); !st.ok()) return st;
    }
    Status st = writer_.write_message(m);
    if (st.code() == ErrorCode::InvalidArgument) {
      if (report_.dropped_messages++ == 0) {
        note("messages of channels whose Channel record was lost are dropped (first: channel " +
             std::to_string(m.channel_id) + ")");
      }
      return Ok{};
    }
    if (st.ok()) ++report_.messages;
    return st;
  }

  void note(std::string text) {
    if (report_.notes.size() < 100) report_.notes.push_back(std::move(text));
  }

  RecoverReport& report_;
  mcap::Writer writer_;
  IdSet schema_ids_, channel_ids_;
  std::map<std::uint16_t, mcap::Schema> fallback_schemas_;
  std::map<std::uint16_t, mcap::Channel> fallback_channels_;
};

}  // namespace

std::string RecoverReport::summary() const {
  std::string out;
  out += "kept " + std::to_string(messages) + " messages, " + std::to_string(schemas) + " schemas, " +
         std::to_string(channels) + " channels, " + std::to_string(attachments) + " attachments, " +
         std::to_string(metadata) + " metadata records from " + std::to_string(chunks) + " complete chunks\n";
  if (input_intact) {
    out += "input intact: read to its end (" + std::to_string(input_size) + " bytes)\n";
  } else {
    out += "input damaged: reading stopped at offset " + std::to_string(stopped_at) + " of " +
           std::to_string(input_size) + ": " + problem + "\n";
  }
  if (incomplete_chunks > 0) {
    out += std::to_string(incomplete_chunks) +
           " incomplete chunk (cut off by the end of the file): its messages are lost\n";
  }
  if (corrupt_chunks > 0) {
    out += std::to_string(corrupt_chunks) +
           " corrupt chunks skipped (CRC or decompression failed): their messages are lost\n";
  }
  if (dropped_messages > 0)
    out += std::to_string(dropped_messages) + " complete messages dropped (channel unknown)\n";
  for (const std::string& n : notes) out += "  " + n + "\n";
  return out;
}

Result<RecoverReport> recover(const std::string& in, const std::string& out, const RecoverOptions& options) {
  RecoverReport report;
  auto input = detail::open_input(in);
  if (!input) return with_context(in + ": ", input.error());
  mcap::ByteSource& file = *input.value();
  report.input_size = file.size();
  if (report.input_size == 0) return Error{in + ": empty file (0 bytes): not an MCAP file; nothing written"};
  if (same_file(in, out)) return Error{out + ": the output must not be the input file"};

  mcap::StreamReader reader;
  mcap::StreamOptions so;
  so.descend_into_chunks = false;  // chunks are decompressed and checked here, one by one
  so.verify_crcs = true;           // data section, attachment and summary CRCs
  if (Status s = reader.open(in, so); !s.ok())
    return Error{in + ": " + s.error().message + "; nothing written"};

  mcap::RecordEntry entry;
  if (!reader.next(entry) || !std::holds_alternative<mcap::Header>(entry.record)) {
    const Status& s = reader.status();
    return Error{in + ": " +
                 (s.ok() ? std::string("no Header record") : mcap::describe_read_error(s.error())) +
                 "; nothing to recover, nothing written"};
  }
  const mcap::Header header = std::get<mcap::Header>(entry.record);

  AtomicFile output;  // the MCAP writer creates the temporary; commit() moves it into place
  output.open_external(out, AtomicFile::Leftovers::Remove);
  Recoverer rec(report);
  if (has_summary(file)) {
    mcap::IndexedReader summary;
    if (summary.open(in).ok() && summary.indexed()) rec.set_fallback(summary.schemas(), summary.channels());
  }
  mcap::WriterOptions wo;
  wo.compression = options.compression;
  wo.chunk_size = options.chunk_size;
  wo.background_compression = true;
  wo.profile = header.profile;
  wo.library = header.library;
  if (Status s = rec.writer().open(output.writer_path(), wo); !s.ok())
    return with_context(out + ": ", s.error());
  auto abandon = [&](const std::string& why) -> Result<RecoverReport> {
    (void)rec.writer().close();
    return Error{out + ": " + why};  // output's destructor removes the temporary
  };

  bool in_summary = false;
  std::optional<std::uint64_t> garbage_at;  // an opcode 0 record: a zero-filled tail, not data
  while (reader.next(entry)) {
    if (const auto* u = std::get_if<mcap::UnknownRecord>(&entry.record); u != nullptr && u->opcode == 0) {
      garbage_at = entry.offset;
      break;
    }
    if (std::holds_alternative<mcap::DataEnd>(entry.record)) in_summary = true;
    if (in_summary) continue;  // the summary is rebuilt; reading on only checks the rest of the file
    Status s = std::holds_alternative<mcap::Chunk>(entry.record)
                   ? rec.chunk(std::get<mcap::Chunk>(entry.record), entry.offset)
                   : rec.copy(entry.record);
    if (!s.ok()) return abandon(s.error().message);
  }
  const Status& status = reader.status();
  report.input_intact = status.ok() && !garbage_at && report.corrupt_chunks == 0;
  report.stopped_at = garbage_at ? *garbage_at : status.ok() ? report.input_size : reader.position();
  if (garbage_at) {
    report.problem = "invalid record (opcode 0x00) at offset " + std::to_string(*garbage_at) +
                     ": the rest of the file is not MCAP records (zero-filled?)";
  } else if (!status.ok()) {
    report.problem = status.error().message;
    if (status.code() == ErrorCode::Truncated) {
      report.problem = "truncated: " + status.error().message;
      // Which record does the file end in? A chunk loses its messages.
      const std::uint64_t left = report.input_size - std::min(report.stopped_at, report.input_size);
      const std::optional<CutRecord> cut = record_at(file, report.stopped_at);
      if (cut && !starts_magic(cut->opcode)) {
        const std::string name = mcap::opcode_name(cut->opcode);
        report.problem = "truncated: the file ends inside a " + name + " record at offset " +
                         std::to_string(report.stopped_at);
        if (cut->content_length) {
          report.problem += " (it claims " + std::to_string(*cut->content_length) + " bytes, " +
                            std::to_string(left - mcap::RecordReader::kPrefixSize) + " remain)";
        }
        if (cut->opcode == mcap::opcode_of<mcap::Chunk>()) report.incomplete_chunks = 1;
      }
    }
    if (in_summary) report.problem += " (in the summary section, after every data record was read)";
    if (report.corrupt_chunks > 0)
      report.problem += "; " + std::to_string(report.corrupt_chunks) + " corrupt chunks";
  } else if (report.corrupt_chunks > 0) {
    report.problem = std::to_string(report.corrupt_chunks) + " corrupt chunks";
  }

  // A damaged input with nothing complete in it gives no output (an empty recording would only
  // pass the damage on under a new name).
  if (!report.input_intact && report.messages == 0 && report.attachments == 0 && report.metadata == 0) {
    return abandon("nothing to recover from " + in + " (" + report.problem +
                   "): it holds no complete message; nothing written");
  }
  if (Status s = rec.writer().close(); !s.ok()) return with_context(out + ": ", s.error());
  if (Status st = output.commit(); !st) return st.error();
  return report;
}

}  // namespace rbsim::mcap_tools
