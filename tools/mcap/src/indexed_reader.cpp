// Indexed reading (spec: Footer, Summary Section, Chunk Index): Footer -> summary -> only the
// chunks a query needs, merged into log-time order.
#include <algorithm>
#include <set>

#include "stream.hpp"
#include "wire.hpp"

namespace rbsim::mcap {

using namespace detail;

namespace {

Error with_context(const Error& e, const std::string& context) {
  return Error{e.message + " (" + context + ")", e.code};
}

struct Pending {
  Timestamp log_time = 0;
  std::uint64_t chunk_offset = 0;
  std::uint64_t record_offset = 0;
  Message message;
};

// Min-heap order: earliest log time first, then file position for stable ordering.
bool later(const Pending& a, const Pending& b) {
  if (a.log_time != b.log_time) return a.log_time > b.log_time;
  if (a.chunk_offset != b.chunk_offset) return a.chunk_offset > b.chunk_offset;
  return a.record_offset > b.record_offset;
}

}  // namespace

struct IndexedReader::Impl {
  std::unique_ptr<ByteSource> source;
  IndexedOptions options;
  bool open = false;
  Header header;
  Footer footer;
  std::map<std::uint16_t, Schema> schemas;
  std::map<std::uint16_t, Channel> channels;
  std::vector<ChunkIndex> chunk_indexes;
  std::vector<AttachmentIndex> attachment_indexes;
  std::vector<MetadataIndex> metadata_indexes;
  std::vector<SummaryOffset> summary_offsets;
  std::optional<Statistics> statistics;

  Status check_open() const {
    if (open) return Ok{};
    return Error{"indexed reader is not open", ErrorCode::NotOpen};
  }

  void learn(Record& record) {
    if (auto* s = std::get_if<Schema>(&record)) {
      if (s->id != 0) schemas.try_emplace(s->id, std::move(*s));
    } else if (auto* c = std::get_if<Channel>(&record)) {
      channels.try_emplace(c->id, std::move(*c));
    }
  }

  Status read_section(std::uint64_t begin, std::uint64_t end, const std::function<void(Record&)>& visit) {
    // Framed to the end of the file (a length past it is a truncation), bounded by the section.
    RecordReader records(*source, begin);
    RecordView rec;
    while (records.position() < end) {
      if (!records.next(rec)) return records.status();
      if (rec.offset + rec.length > end) {
        return Error{"summary record at offset " + std::to_string(rec.offset) + " overruns its section",
                     ErrorCode::Malformed};
      }
      auto record = parse_record(rec.opcode, rec.content);
      if (!record.ok()) return with_context(record.error(), "summary offset " + std::to_string(rec.offset));
      visit(record.value());
    }
    return Ok{};
  }

  Status read_header() {
    if (source->size() == 0) return Error{"empty file", ErrorCode::Truncated};
    // Not MCAP, or cut off inside the magic: check_magic says which (describe_read_error words it).
    if (Status st = check_magic(*source, 0); !st.ok()) return st;
    RecordView rec;
    if (Status st = read_record(*source, sizeof kMagic, rec); !st.ok()) return st;
    auto parsed = parse_record(rec.opcode, rec.content);
    if (!parsed.ok() || rec.opcode != static_cast<std::uint8_t>(Opcode::Header)) {
      return Error{"first record is not a valid Header", ErrorCode::Malformed};
    }
    header = std::get<Header>(std::move(parsed).value());
    return Ok{};
  }

  Status load(std::unique_ptr<ByteSource> s, const IndexedOptions& opts) {
    *this = Impl{};
    source = std::move(s);
    options = opts;
    if (Status st = read_header(); !st.ok()) return st;
    // Footer and trailing magic sit at fixed distances from the end (spec: Footer).
    auto read = read_footer(*source);
    if (!read.ok()) return read.error();
    footer = read.value();
    const std::uint64_t footer_offset = mcap::footer_offset(source->size());
    ByteView view;

    const std::uint64_t summary_end =
        footer.summary_offset_start != 0 ? footer.summary_offset_start : footer_offset;
    if ((footer.summary_start != 0 && (footer.summary_start < 8 || footer.summary_start > summary_end)) ||
        (footer.summary_offset_start != 0 &&
         (footer.summary_offset_start < 8 || footer.summary_offset_start > footer_offset))) {
      return Error{"Footer offsets point outside the file", ErrorCode::Malformed};
    }
    if (options.verify_summary_crc && footer.summary_crc != 0) {
      // Covers the summary (if any) through Footer.summary_offset_start.
      const std::uint64_t crc_start = footer.summary_start != 0          ? footer.summary_start
                                      : footer.summary_offset_start != 0 ? footer.summary_offset_start
                                                                         : footer_offset;
      if (Status st = source->read(crc_start, footer_offset + kRecordPrefix + 16 - crc_start, view);
          !st.ok()) {
        return st;
      }
      const std::uint32_t crc = crc32(view);
      if (crc != footer.summary_crc) {
        return Error{
            "summary CRC mismatch: computed " + crc_text(crc) + ", stored " + crc_text(footer.summary_crc),
            ErrorCode::CrcMismatch};
      }
    }
    if (footer.summary_start != 0) {
      Status st = read_section(footer.summary_start, summary_end, [this](Record& r) {
        if (auto* ci = std::get_if<ChunkIndex>(&r)) {
          chunk_indexes.push_back(std::move(*ci));
        } else if (auto* ai = std::get_if<AttachmentIndex>(&r)) {
          attachment_indexes.push_back(std::move(*ai));
        } else if (auto* mi = std::get_if<MetadataIndex>(&r)) {
          metadata_indexes.push_back(std::move(*mi));
        } else if (auto* stats = std::get_if<Statistics>(&r)) {
          statistics = std::move(*stats);
        } else {
          learn(r);
        }
      });
      if (!st.ok()) return st;
    }
    if (footer.summary_offset_start != 0) {
      Status st = read_section(footer.summary_offset_start, footer_offset, [this](Record& r) {
        if (auto* so = std::get_if<SummaryOffset>(&r)) summary_offsets.push_back(*so);
      });
      if (!st.ok()) return st;
    }
    open = true;
    if (chunk_indexes.empty()) return scan(nullptr);  // no index: learn schemas/channels linearly
    return Ok{};
  }

  // Linear fallback for unindexed files: every record in order, messages handed to `on_message`.
  Status scan(const std::function<void(Message&, std::optional<std::uint64_t>, std::uint64_t)>& on_message) {
    StreamOptions so;
    so.verify_crcs = options.verify_chunk_crcs;
    Streamer streamer(*source, so);
    RecordEntry entry;
    while (streamer.next(entry)) {
      if (auto* m = std::get_if<Message>(&entry.record)) {
        if (on_message) on_message(*m, entry.chunk_offset, entry.offset);
      } else {
        learn(entry.record);
      }
    }
    return streamer.status();
  }

  Status load_chunk(const ChunkIndex& index, const std::function<void(Message&, std::uint64_t)>& on_message) {
    const std::string where = "chunk at offset " + std::to_string(index.chunk_start_offset);
    RecordView rec;
    if (Status s = read_record(*source, index.chunk_start_offset, rec); !s.ok())
      return with_context(s.error(), where);
    auto record = parse_record(rec.opcode, rec.content);
    if (!record.ok() || rec.opcode != static_cast<std::uint8_t>(Opcode::Chunk)) {
      return Error{"chunk index points at no Chunk (" + where + ")", ErrorCode::Malformed};
    }
    Bytes data;
    if (Status s = decompress_chunk(std::get<Chunk>(record.value()), data, options.verify_chunk_crcs);
        !s.ok()) {
      return with_context(s.error(), where);
    }
    ViewSource chunk_source(data);
    RecordReader records(chunk_source);
    while (records.next(rec)) {
      auto inner = parse_record(rec.opcode, rec.content);
      if (!inner.ok()) return with_context(inner.error(), where);
      if (auto* m = std::get_if<Message>(&inner.value())) {
        on_message(*m, rec.offset);
      } else {
        learn(inner.value());
      }
    }
    if (!records.status().ok()) return Error{"record cut off inside " + where, ErrorCode::Malformed};
    return Ok{};
  }
};

IndexedReader::IndexedReader() : impl_(std::make_unique<Impl>()) {}
IndexedReader::~IndexedReader() = default;

Status IndexedReader::open(const std::string& path, const IndexedOptions& options) {
  auto source = open_file_source(path);
  if (!source.ok()) return source.error();
  return impl_->load(std::move(source).value(), options);
}

Status IndexedReader::open_buffer(Bytes data, const IndexedOptions& options) {
  return impl_->load(make_buffer_source(std::move(data)), options);
}

Status IndexedReader::read_messages(const ReadMessagesOptions& options,
                                    const std::function<bool(const MessageEntry&)>& on_message) {
  Impl& r = *impl_;
  if (Status s = r.check_open(); !s.ok()) return s;
  const std::set<std::string> topics(options.topics.begin(), options.topics.end());
  auto in_time = [&](Timestamp t) {
    return t >= options.start_time && (options.end_time == kMaxTime || t < options.end_time);
  };
  auto wanted = [&](const Message& m) {
    if (!in_time(m.log_time)) return false;
    if (topics.empty()) return true;
    auto it = r.channels.find(m.channel_id);
    return it != r.channels.end() && topics.count(it->second.topic) > 0;
  };
  auto deliver = [&](Pending& p) {
    const auto ch = r.channels.find(p.message.channel_id);
    const Channel* channel = ch == r.channels.end() ? nullptr : &ch->second;
    const Schema* schema = nullptr;
    if (channel != nullptr && channel->schema_id != 0) {
      const auto sc = r.schemas.find(channel->schema_id);
      if (sc != r.schemas.end()) schema = &sc->second;
    }
    std::optional<std::uint64_t> chunk_offset;
    if (p.chunk_offset != UINT64_MAX) chunk_offset = p.chunk_offset;
    return on_message(MessageEntry{p.message, channel, schema, chunk_offset});
  };

  std::vector<Pending> heap;
  if (r.chunk_indexes.empty()) {
    Status s = r.scan([&](Message& m, std::optional<std::uint64_t> chunk, std::uint64_t offset) {
      if (wanted(m)) heap.push_back({m.log_time, chunk.value_or(UINT64_MAX), offset, std::move(m)});
    });
    if (!s.ok()) return s;
    // Messages outside chunks sort by their file offset; inside a chunk by (chunk, offset).
    std::stable_sort(heap.begin(), heap.end(),
                     [](const Pending& a, const Pending& b) { return a.log_time < b.log_time; });
    for (Pending& p : heap) {
      if (!deliver(p)) break;
    }
    return Ok{};
  }

  // Chunks that may hold a wanted message: overlapping the time range and, when their message
  // index lists channels we know, carrying one of the wanted topics.
  std::vector<const ChunkIndex*> chunks;
  for (const ChunkIndex& ci : r.chunk_indexes) {
    if (ci.message_end_time < options.start_time) continue;
    if (options.end_time != kMaxTime && ci.message_start_time >= options.end_time) continue;
    if (std::find(options.skip_chunks.begin(), options.skip_chunks.end(), ci.chunk_start_offset) !=
        options.skip_chunks.end())
      continue;
    bool relevant = topics.empty() || ci.message_index_offsets.empty();
    for (const auto& [channel_id, offset] : ci.message_index_offsets) {
      auto it = r.channels.find(channel_id);
      relevant = relevant || it == r.channels.end() || topics.count(it->second.topic) > 0;
    }
    if (relevant) chunks.push_back(&ci);
  }
  std::stable_sort(chunks.begin(), chunks.end(), [](const ChunkIndex* a, const ChunkIndex* b) {
    return a->message_start_time != b->message_start_time ? a->message_start_time < b->message_start_time
                                                          : a->chunk_start_offset < b->chunk_start_offset;
  });
  // Merge: before handing out the earliest pending message, load every chunk that could start
  // at or before it. Only the chunks overlapping the current read position are held in memory.
  std::size_t next_chunk = 0;
  for (;;) {
    while (next_chunk < chunks.size() &&
           (heap.empty() || chunks[next_chunk]->message_start_time <= heap.front().log_time)) {
      const ChunkIndex& ci = *chunks[next_chunk++];
      Status s = r.load_chunk(ci, [&](Message& m, std::uint64_t offset) {
        if (!wanted(m)) return;
        heap.push_back({m.log_time, ci.chunk_start_offset, offset, std::move(m)});
        std::push_heap(heap.begin(), heap.end(), later);
      });
      if (!s.ok()) return s;
    }
    if (heap.empty()) return Ok{};
    std::pop_heap(heap.begin(), heap.end(), later);
    Pending p = std::move(heap.back());
    heap.pop_back();
    if (!deliver(p)) return Ok{};
  }
}

Result<std::vector<Message>> IndexedReader::read_all_messages(const ReadMessagesOptions& options) {
  std::vector<Message> out;
  Status s = read_messages(options, [&out](const MessageEntry& e) {
    out.push_back(e.message);
    return true;
  });
  if (!s.ok()) return s.error();
  return out;
}

Result<Chunk> IndexedReader::read_chunk(const ChunkIndex& index, bool verify) {
  if (Status s = impl_->check_open(); !s.ok()) return s.error();
  const std::string where = "chunk at offset " + std::to_string(index.chunk_start_offset);
  RecordView rec;
  if (Status s = read_record(*impl_->source, index.chunk_start_offset, rec); !s.ok())
    return with_context(s.error(), where);
  auto record = parse_record(rec.opcode, rec.content);
  if (!record.ok() || rec.opcode != static_cast<std::uint8_t>(Opcode::Chunk)) {
    return Error{"chunk index points at no Chunk (" + where + ")", ErrorCode::Malformed};
  }
  Chunk chunk = std::get<Chunk>(std::move(record).value());
  if (verify) {
    Bytes data;
    if (Status s = decompress_chunk(chunk, data, true); !s.ok()) return with_context(s.error(), where);
  }
  return chunk;
}

Result<std::vector<MessageIndex>> IndexedReader::read_message_indexes(const ChunkIndex& index) {
  if (Status s = impl_->check_open(); !s.ok()) return s.error();
  std::vector<MessageIndex> out;
  for (const auto& [channel_id, offset] : index.message_index_offsets) {
    RecordView rec;
    if (Status s = read_record(*impl_->source, offset, rec); !s.ok()) return s.error();
    auto record = parse_record(rec.opcode, rec.content);
    if (!record.ok() || rec.opcode != static_cast<std::uint8_t>(Opcode::MessageIndex) ||
        std::get<MessageIndex>(record.value()).channel_id != channel_id) {
      return Error{"chunk index points at no Message Index of channel " + std::to_string(channel_id) +
                       " (offset " + std::to_string(offset) + ")",
                   ErrorCode::Malformed};
    }
    out.push_back(std::get<MessageIndex>(std::move(record).value()));
  }
  return out;
}

Result<Attachment> IndexedReader::read_attachment(const AttachmentIndex& index) {
  if (Status s = impl_->check_open(); !s.ok()) return s.error();
  RecordView rec;
  if (Status s = read_record(*impl_->source, index.offset, rec); !s.ok()) return s.error();
  auto record = parse_record(rec.opcode, rec.content);
  if (!record.ok()) return record.error();
  if (rec.opcode != static_cast<std::uint8_t>(Opcode::Attachment)) {
    return Error{"attachment index points at no Attachment", ErrorCode::Malformed};
  }
  Attachment a = std::get<Attachment>(std::move(record).value());
  if (Status s = check_attachment_crc(rec.content, a); !s.ok()) return s.error();
  return a;
}

Result<Metadata> IndexedReader::read_metadata(const MetadataIndex& index) {
  if (Status s = impl_->check_open(); !s.ok()) return s.error();
  RecordView rec;
  if (Status s = read_record(*impl_->source, index.offset, rec); !s.ok()) return s.error();
  auto record = parse_record(rec.opcode, rec.content);
  if (!record.ok()) return record.error();
  if (rec.opcode != static_cast<std::uint8_t>(Opcode::Metadata)) {
    return Error{"metadata index points at no Metadata", ErrorCode::Malformed};
  }
  return std::get<Metadata>(std::move(record).value());
}

Status IndexedReader::verify_data_section_crc() {
  if (Status s = impl_->check_open(); !s.ok()) return s;
  StreamOptions so;
  so.descend_into_chunks = false;
  so.verify_crcs = true;
  Streamer streamer(*impl_->source, so);
  RecordEntry entry;
  while (streamer.next(entry)) {
    if (std::holds_alternative<DataEnd>(entry.record)) return Ok{};
  }
  if (!streamer.status().ok()) return streamer.status();
  return Error{"no DataEnd record", ErrorCode::Malformed};
}

bool IndexedReader::indexed() const {
  return !impl_->chunk_indexes.empty();
}
std::uint64_t IndexedReader::file_size() const {
  return impl_->source ? impl_->source->size() : 0;
}
const Header& IndexedReader::header() const {
  return impl_->header;
}
const Footer& IndexedReader::footer() const {
  return impl_->footer;
}
const std::map<std::uint16_t, Schema>& IndexedReader::schemas() const {
  return impl_->schemas;
}
const std::map<std::uint16_t, Channel>& IndexedReader::channels() const {
  return impl_->channels;
}
const std::vector<ChunkIndex>& IndexedReader::chunk_indexes() const {
  return impl_->chunk_indexes;
}
const std::vector<AttachmentIndex>& IndexedReader::attachment_indexes() const {
  return impl_->attachment_indexes;
}
const std::vector<MetadataIndex>& IndexedReader::metadata_indexes() const {
  return impl_->metadata_indexes;
}
const std::vector<SummaryOffset>& IndexedReader::summary_offsets() const {
  return impl_->summary_offsets;
}
const std::optional<Statistics>& IndexedReader::statistics() const {
  return impl_->statistics;
}

}  // namespace rbsim::mcap
