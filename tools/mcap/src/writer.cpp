// Writer: <Magic><Header><Data section><DataEnd>[<Summary>][<Summary Offsets>]<Footer><Magic>.
//
// Uncompressed chunks written to a file that can seek (or to memory) are streamed: the Chunk
// header goes out first with placeholder sizes (record length UINT64_MAX, so until the chunk is
// complete a reader sees a truncated record, as it would a chunk cut off mid-write), each record
// follows straight from the caller's bytes, and the header is overwritten once the chunk is full.
// No copy of the records, and one CRC pass over them: the data section CRC is combined from the
// chunk's (crc32_combine). Attachments and metadata, which never go inside a chunk, close it first.
// Compressed chunks are built in memory, compressed whole and then written.
#include <algorithm>
#include <optional>

#include "byte_sink.hpp"
#include "codec.hpp"
#include "wire.hpp"

namespace rbsim::mcap {

using namespace detail;

struct Writer::Impl {
  WriterOptions options;
  std::unique_ptr<ByteSink> sink;
  std::unique_ptr<Compressor> compressor;
  Status error;  // sticky: the first failure is returned by every later call
  bool open = false;
  bool in_summary = false;

  std::uint64_t offset = 0;       // bytes written so far
  std::uint32_t data_crc = 0;     // over every byte before DataEnd (spec: Data End)
  std::uint32_t summary_crc = 0;  // from the end of DataEnd through Footer.summary_offset_start

  std::map<std::uint16_t, Schema> schemas;
  std::map<std::uint16_t, Channel> channels;
  Statistics stats;
  std::vector<ChunkIndex> chunk_indexes;
  std::vector<AttachmentIndex> attachment_indexes;
  std::vector<MetadataIndex> metadata_indexes;

  // What a chunk's index needs besides its records: a message index per channel (spec: Message
  // Index offsets are relative to the start of the uncompressed records) and its time range.
  struct ChunkMeta {
    std::map<std::uint16_t, std::vector<std::pair<Timestamp, std::uint64_t>>> message_index;
    Timestamp start_time = 0;
    Timestamp end_time = 0;
    bool has_messages = false;
  };
  Bytes chunk;  // the open chunk's uncompressed records
  ChunkMeta chunk_meta;
  // Streamed uncompressed chunks: the open chunk's file offset, its records' size and CRC so far.
  bool stream = false;
  bool streaming = false;  // a streamed chunk is open
  std::uint64_t stream_start = 0;
  std::uint64_t stream_size = 0;
  std::uint32_t stream_crc = 0;
  std::unique_ptr<ChunkWorker> worker;  // background_compression: the chunk being compressed
  ChunkMeta worker_meta;                // and its index data

  Bytes scratch;

  Status check_open() const {
    if (!error.ok()) return error;
    if (!open) return Error{"writer is not open", ErrorCode::NotOpen};
    return Ok{};
  }

  Status write(ByteView bytes) {
    if (!error.ok()) return error;
    if (options.enable_crcs) {
      std::uint32_t& crc = in_summary ? summary_crc : data_crc;
      crc = crc32(bytes, crc);
    }
    offset += bytes.size();
    Status s = sink->write(bytes);
    if (!s.ok()) error = s;
    return s;
  }

  // Serialises into the pending chunk when chunking (Schema/Channel/Message), else to the file.
  Status emit(const Record& record, bool into_chunk) {
    if (into_chunk && stream) {
      scratch.clear();
      serialize_record(record, scratch);
      return stream_records(scratch);
    }
    if (into_chunk) {
      serialize_record(record, chunk);
      return Ok{};
    }
    scratch.clear();
    serialize_record(record, scratch);
    return write(scratch);
  }

  Status begin(std::unique_ptr<ByteSink> s, const WriterOptions& opts) {
    *this = Impl{};
    options = opts;
    sink = std::move(s);
    stream = options.use_chunks && options.compression == Compression::None && sink->seekable();
    if (stream) {
      // Nothing to compress: no worker.
    } else if (options.use_chunks && options.background_compression) {
      worker =
          std::make_unique<ChunkWorker>(options.compression, options.compression_level, options.enable_crcs);
    }
    if (!stream) compressor = std::make_unique<Compressor>(options.compression, options.compression_level);
    open = true;
    Status st = write(ByteView(kMagic));
    if (!st.ok()) return st;
    return emit(Header{options.profile, options.library}, false);
  }

  // Chunk header of a chunk with `records` bytes of records and `payload` bytes of (compressed)
  // payload, through the payload's length prefix.
  void chunk_header(Bytes& out, std::uint64_t records, std::uint64_t payload, std::uint32_t crc,
                    const ChunkMeta& meta) const {
    const std::string_view compression = to_string(options.compression);
    put_u8(out, static_cast<std::uint8_t>(Opcode::Chunk));
    put_u64(out, 8 + 8 + 8 + 4 + 4 + compression.size() + 8 + payload);
    put_u64(out, meta.has_messages ? meta.start_time : 0);
    put_u64(out, meta.has_messages ? meta.end_time : 0);
    put_u64(out, records);
    put_u32(out, crc);
    put_string(out, compression);
    put_u64(out, payload);
  }

  // Appends records to the streamed chunk, opening it (its header with placeholder sizes) first.
  Status stream_records(ByteView bytes) {
    if (!error.ok()) return error;
    Status s;
    if (!streaming) {
      Bytes header;
      chunk_header(header, 0, 0, 0, ChunkMeta{});
      for (std::size_t i = 1; i < 9; ++i) header[i] = std::byte{0xFF};  // record length UINT64_MAX
      stream_start = offset;  // stream_size and stream_crc are 0 here
      streaming = true;
      if (!(s = sink->write(header)).ok()) return error = s;
      offset += header.size();  // its CRC is taken once its final bytes are known
    }
    if (options.enable_crcs) stream_crc = crc32(bytes, stream_crc);
    stream_size += bytes.size();
    offset += bytes.size();
    if (!(s = sink->write(bytes)).ok()) error = s;
    return s;
  }

  // Completes the streamed chunk: its header rewritten with the final sizes, CRCs and times.
  Status finish_streamed_chunk() {
    if (!streaming) return Ok{};
    streaming = false;
    scratch.clear();
    chunk_header(scratch, stream_size, stream_size, options.enable_crcs ? stream_crc : 0, chunk_meta);
    Status s = sink->write_at(stream_start, scratch);
    if (!s.ok()) return error = s;
    if (options.enable_crcs) data_crc = crc32_combine(crc32(scratch, data_crc), stream_crc, stream_size);
    ChunkIndex index;
    index.message_start_time = chunk_meta.has_messages ? chunk_meta.start_time : 0;
    index.message_end_time = chunk_meta.has_messages ? chunk_meta.end_time : 0;
    index.chunk_start_offset = stream_start;
    index.chunk_length = offset - stream_start;
    index.compressed_size = index.uncompressed_size = stream_size;
    stream_size = 0;
    stream_crc = 0;
    s = finish_chunk(index, chunk_meta);
    chunk_meta = ChunkMeta{};
    return s;
  }

  // Closes the open chunk: streamed, compressed here, or handed to the worker (which first
  // finishes and writes the chunk before it, keeping file order).
  Status flush_chunk() {
    if (stream) return finish_streamed_chunk();
    if (chunk.empty()) return Ok{};
    Status s;
    // The worker takes the chunk when it is free. While it is still busy with the chunk before,
    // this one is compressed here meanwhile (two cores at work), and both are written in order.
    if (worker && (!worker->pending() || worker->finished())) {
      if (!(s = finish_pending()).ok()) return s;
      std::swap(chunk, worker->records());  // `chunk` gets the worker's emptied buffer back
      worker_meta = std::move(chunk_meta);
      chunk_meta = ChunkMeta{};
      worker->submit();
      return Ok{};
    }
    // An uncompressed chunk is written straight from `chunk`, without a copy through the compressor.
    ByteView payload = chunk;
    if (options.compression != Compression::None && !(s = compressor->compress(chunk, payload)).ok()) {
      return error = s;
    }
    const std::uint32_t crc = options.enable_crcs ? crc32(chunk) : 0;
    if (!(s = finish_pending()).ok()) return s;  // the worker's chunk first (none without a worker)
    s = write_chunk(chunk, payload, crc, chunk_meta);
    chunk.clear();
    chunk_meta = ChunkMeta{};
    return s;
  }

  Status write_compressed_chunk() {
    return worker && worker->pending() && worker->finished() ? finish_pending() : Ok{};
  }

  // Writes the chunk the worker holds, once compressed (waiting for it if need be).
  Status finish_pending() {
    if (!worker || !worker->pending()) return Ok{};
    Status s = worker->wait();
    if (!s.ok()) {
      worker->release();
      return error = s;
    }
    s = write_chunk(worker->records(), worker->payload(), worker->crc(), worker_meta);
    worker->release();
    worker_meta = ChunkMeta{};
    return s;
  }

  // `records` are the uncompressed records (their size is the chunk's uncompressed size unless
  // `uncompressed_size` says otherwise: a copied chunk, whose records stay compressed).
  Status write_chunk(ByteView records, ByteView payload, std::uint32_t crc, ChunkMeta& meta,
                     std::optional<std::uint64_t> uncompressed_size = std::nullopt) {
    Status s;
    const std::uint64_t records_size = uncompressed_size.value_or(records.size());
    // Chunk header written by hand so the (possibly large) records are not copied again.
    scratch.clear();
    chunk_header(scratch, records_size, payload.size(), crc, meta);
    ChunkIndex index;
    index.message_start_time = meta.has_messages ? meta.start_time : 0;
    index.message_end_time = meta.has_messages ? meta.end_time : 0;
    index.chunk_start_offset = offset;
    index.compressed_size = payload.size();
    index.uncompressed_size = records_size;
    if (!(s = write(scratch)).ok() || !(s = write(payload)).ok()) return s;
    index.chunk_length = offset - index.chunk_start_offset;
    return finish_chunk(index, meta);
  }

  // After a chunk record: its message indexes, its chunk index, and the bytes to the OS.
  Status finish_chunk(ChunkIndex& index, ChunkMeta& meta) {
    Status s;
    index.compression = std::string(to_string(options.compression));
    if (options.emit_message_indexes) {
      const std::uint64_t start = offset;
      for (auto& [channel_id, entries] : meta.message_index) {
        index.message_index_offsets[channel_id] = offset;
        if (!(s = emit(MessageIndex{channel_id, std::move(entries)}, false)).ok()) return s;
      }
      index.message_index_length = offset - start;
    }
    if (options.emit_chunk_indexes) chunk_indexes.push_back(std::move(index));
    ++stats.chunk_count;
    // A completed chunk reaches the OS now, so a killed process leaves it readable.
    if (!(s = sink->flush()).ok()) error = s;
    return s;
  }

  template <typename T>
  Status write_group(Opcode opcode, const std::vector<T>& records, std::vector<SummaryOffset>& groups) {
    if (records.empty()) return Ok{};
    const std::uint64_t start = offset;
    for (const T& r : records) {
      Status s = emit(r, false);
      if (!s.ok()) return s;
    }
    groups.push_back({static_cast<std::uint8_t>(opcode), start, offset - start});
    return Ok{};
  }

  Status finish() {
    Status s = flush_chunk();
    if (s.ok()) s = finish_pending();
    worker.reset();
    if (!s.ok()) return s;
    if (!(s = emit(DataEnd{options.enable_crcs ? data_crc : 0}, false)).ok()) return s;
    in_summary = true;
    const std::uint64_t summary_start = offset;
    // Summary records grouped by opcode (spec: Summary Section), one Summary Offset per group.
    std::vector<SummaryOffset> groups;
    std::vector<Schema> schema_group;
    std::vector<Channel> channel_group;
    std::vector<Statistics> stats_group;
    for (const auto& [id, schema] : schemas) {
      if (options.repeat_schemas) schema_group.push_back(schema);
    }
    for (const auto& [id, channel] : channels) {
      if (options.repeat_channels) channel_group.push_back(channel);
    }
    if (options.emit_statistics) stats_group.push_back(stats);
    if (!(s = write_group(Opcode::Schema, schema_group, groups)).ok() ||
        !(s = write_group(Opcode::Channel, channel_group, groups)).ok() ||
        !(s = write_group(Opcode::Statistics, stats_group, groups)).ok() ||
        !(s = write_group(Opcode::ChunkIndex, chunk_indexes, groups)).ok() ||
        !(s = write_group(Opcode::AttachmentIndex, attachment_indexes, groups)).ok() ||
        !(s = write_group(Opcode::MetadataIndex, metadata_indexes, groups)).ok()) {
      return s;
    }
    Footer footer;
    footer.summary_start = offset > summary_start ? summary_start : 0;
    if (options.emit_summary_offsets && !groups.empty()) {
      footer.summary_offset_start = offset;
      for (const SummaryOffset& g : groups) {
        if (!(s = emit(g, false)).ok()) return s;
      }
    }
    // The summary CRC ends after summary_offset_start, so the Footer is written in two parts.
    scratch.clear();
    put_u8(scratch, static_cast<std::uint8_t>(Opcode::Footer));
    put_u64(scratch, kFooterContent);
    put_u64(scratch, footer.summary_start);
    put_u64(scratch, footer.summary_offset_start);
    if (!(s = write(scratch)).ok()) return s;
    scratch.clear();
    put_u32(scratch, options.enable_crcs ? summary_crc : 0);
    scratch.insert(scratch.end(), std::begin(kMagic), std::end(kMagic));
    if (!(s = write(scratch)).ok()) return s;
    if (!(s = sink->close()).ok()) error = s;
    return s;
  }
};

Writer::Writer() : impl_(std::make_unique<Impl>()) {}

Writer::~Writer() {
  if (impl_->open) (void)close();
}

Status Writer::open(const std::string& path, const WriterOptions& options) {
  if (impl_->open) return Error{"writer is already open", ErrorCode::InvalidArgument};
  auto sink = open_file_sink(path);
  if (!sink.ok()) return sink.error();
  return impl_->begin(std::move(sink).value(), options);
}

Status Writer::open_buffer(const WriterOptions& options) {
  if (impl_->open) return Error{"writer is already open", ErrorCode::InvalidArgument};
  return impl_->begin(make_buffer_sink(), options);
}

Status Writer::add_schema(const Schema& schema) {
  Impl& w = *impl_;
  if (Status s = w.check_open(); !s.ok()) return s;
  if (schema.id == 0) return Error{"schema id 0 is reserved", ErrorCode::InvalidArgument};
  // Spec: "Any two schema records sharing a common ID must be identical".
  if (auto it = w.schemas.find(schema.id); it != w.schemas.end()) {
    const Schema& old = it->second;
    if (old.name == schema.name && old.encoding == schema.encoding && old.data == schema.data) {
      return Ok{};
    }
    return Error{"schema id " + std::to_string(schema.id) + " redefined", ErrorCode::InvalidArgument};
  }
  if (Status s = w.emit(schema, w.options.use_chunks); !s.ok()) return s;
  w.schemas.emplace(schema.id, schema);
  w.stats.schema_count = static_cast<std::uint16_t>(w.schemas.size());
  return Ok{};
}

Result<std::uint16_t> Writer::add_schema(std::string_view name, std::string_view encoding, ByteView data) {
  const std::uint16_t id =
      static_cast<std::uint16_t>(impl_->schemas.empty() ? 1 : impl_->schemas.rbegin()->first + 1);
  if (id == 0) return Error{"schema ids exhausted", ErrorCode::InvalidArgument};
  Status s =
      add_schema(Schema{id, std::string(name), std::string(encoding), Bytes(data.begin(), data.end())});
  if (!s.ok()) return s.error();
  return id;
}

Status Writer::add_channel(const Channel& channel) {
  Impl& w = *impl_;
  if (Status s = w.check_open(); !s.ok()) return s;
  if (channel.schema_id != 0 && w.schemas.count(channel.schema_id) == 0) {
    return Error{"unknown schema id " + std::to_string(channel.schema_id), ErrorCode::InvalidArgument};
  }
  if (auto it = w.channels.find(channel.id); it != w.channels.end()) {
    const Channel& old = it->second;
    if (old.schema_id == channel.schema_id && old.topic == channel.topic &&
        old.message_encoding == channel.message_encoding && old.metadata == channel.metadata) {
      return Ok{};
    }
    return Error{"channel id " + std::to_string(channel.id) + " redefined", ErrorCode::InvalidArgument};
  }
  if (Status s = w.emit(channel, w.options.use_chunks); !s.ok()) return s;
  w.channels.emplace(channel.id, channel);
  w.stats.channel_count = static_cast<std::uint32_t>(w.channels.size());
  return Ok{};
}

Result<std::uint16_t> Writer::add_channel(std::uint16_t schema_id, std::string_view topic,
                                          std::string_view message_encoding, const KeyValueMap& metadata) {
  const std::uint16_t id =
      static_cast<std::uint16_t>(impl_->channels.empty() ? 1 : impl_->channels.rbegin()->first + 1);
  if (id == 0) return Error{"channel ids exhausted", ErrorCode::InvalidArgument};
  Status s = add_channel(Channel{id, schema_id, std::string(topic), std::string(message_encoding), metadata});
  if (!s.ok()) return s.error();
  return id;
}

Status Writer::write_message(const Message& message) {
  return write_message(message.channel_id, message.sequence, message.log_time, message.publish_time,
                       message.data);
}

Status Writer::write_message(std::uint16_t channel_id, std::uint32_t sequence, Timestamp log_time,
                             Timestamp publish_time, ByteView data) {
  Impl& w = *impl_;
  if (Status s = w.check_open(); !s.ok()) return s;
  if (w.channels.count(channel_id) == 0) {
    return Error{"unknown channel id " + std::to_string(channel_id), ErrorCode::InvalidArgument};
  }
  Statistics& st = w.stats;
  st.message_start_time = st.message_count == 0 ? log_time : std::min(st.message_start_time, log_time);
  st.message_end_time = st.message_count == 0 ? log_time : std::max(st.message_end_time, log_time);
  ++st.message_count;
  ++st.channel_message_counts[channel_id];
  // Message layout by hand: its data is the rest of the record, so no copy into a Message.
  Bytes& out = w.options.use_chunks && !w.stream ? w.chunk : w.scratch;
  if (&out == &w.scratch) out.clear();
  const std::uint64_t record_offset = w.stream ? w.stream_size : out.size();
  put_u8(out, static_cast<std::uint8_t>(Opcode::Message));
  put_u64(out, 2 + 4 + 8 + 8 + data.size());
  put_u16(out, channel_id);
  put_u32(out, sequence);
  put_u64(out, log_time);
  put_u64(out, publish_time);
  if (w.stream) {
    Status s = w.stream_records(out);
    if (s.ok()) s = w.stream_records(data);
    if (!s.ok()) return s;
  } else {
    put_raw(out, data);
  }
  if (!w.options.use_chunks) return w.write(out);
  Impl::ChunkMeta& meta = w.chunk_meta;
  meta.message_index[channel_id].emplace_back(log_time, record_offset);
  meta.start_time = meta.has_messages ? std::min(meta.start_time, log_time) : log_time;
  meta.end_time = meta.has_messages ? std::max(meta.end_time, log_time) : log_time;
  meta.has_messages = true;
  // A compressed chunk goes to the file as soon as it is ready, not only when the next one is full.
  if (Status s = w.write_compressed_chunk(); !s.ok()) return s;
  if ((w.stream ? w.stream_size : w.chunk.size()) >= w.options.chunk_size) return w.flush_chunk();
  return Ok{};
}

Status Writer::add_attachment(Timestamp log_time, Timestamp create_time, std::string_view name,
                              std::string_view media_type, ByteView data) {
  Impl& w = *impl_;
  if (Status s = w.check_open(); !s.ok()) return s;
  if (Status s = w.finish_pending(); !s.ok()) return s;
  if (Status s = w.finish_streamed_chunk(); !s.ok()) return s;
  // Attachments never go inside chunks (spec: Attachment); the CRC covers every preceding field.
  Bytes& out = w.scratch;
  out.clear();
  put_u8(out, static_cast<std::uint8_t>(Opcode::Attachment));
  put_u64(out, 8 + 8 + 4 + name.size() + 4 + media_type.size() + 8 + data.size() + 4);
  put_u64(out, log_time);
  put_u64(out, create_time);
  put_string(out, name);
  put_string(out, media_type);
  put_bytes64(out, data);
  put_u32(out, w.options.enable_crcs ? crc32(ByteView(out).subspan(kRecordPrefix)) : 0);
  AttachmentIndex index{
      w.offset, out.size(), log_time, create_time, data.size(), std::string(name), std::string(media_type)};
  if (Status s = w.write(out); !s.ok()) return s;
  if (w.options.emit_attachment_indexes) w.attachment_indexes.push_back(std::move(index));
  ++w.stats.attachment_count;
  return Ok{};
}

Status Writer::add_metadata(std::string_view name, const KeyValueMap& metadata) {
  Impl& w = *impl_;
  if (Status s = w.check_open(); !s.ok()) return s;
  if (Status s = w.finish_pending(); !s.ok()) return s;
  if (Status s = w.finish_streamed_chunk(); !s.ok()) return s;
  const std::uint64_t start = w.offset;
  if (Status s = w.emit(Metadata{std::string(name), metadata}, false); !s.ok()) return s;
  if (w.options.emit_metadata_indexes) {
    w.metadata_indexes.push_back({start, w.offset - start, std::string(name)});
  }
  ++w.stats.metadata_count;
  return Ok{};
}

Status Writer::copy_chunk(const Chunk& chunk, const std::vector<MessageIndex>& indexes) {
  Impl& w = *impl_;
  if (Status s = w.check_open(); !s.ok()) return s;
  if (!w.options.use_chunks)
    return Error{"copy_chunk: the writer writes no chunks", ErrorCode::InvalidArgument};
  if (chunk.compression != to_string(w.options.compression)) {
    return Error{"copy_chunk: a chunk compressed with \"" + chunk.compression + "\" into a file of \"" +
                     std::string(to_string(w.options.compression)) + "\" chunks",
                 ErrorCode::InvalidArgument};
  }
  Impl::ChunkMeta meta;
  std::uint64_t count = 0;
  for (const MessageIndex& mi : indexes) {
    if (w.channels.count(mi.channel_id) == 0) {
      return Error{"copy_chunk: unknown channel id " + std::to_string(mi.channel_id),
                   ErrorCode::InvalidArgument};
    }
    count += mi.records.size();
    auto& entries = meta.message_index[mi.channel_id];
    entries.insert(entries.end(), mi.records.begin(), mi.records.end());
  }
  // The open chunk (and the one being compressed) go first: file order is kept.
  if (Status s = w.flush_chunk(); !s.ok()) return s;
  if (Status s = w.finish_pending(); !s.ok()) return s;
  meta.start_time = chunk.message_start_time;
  meta.end_time = chunk.message_end_time;
  meta.has_messages = count > 0;
  Statistics& st = w.stats;
  if (count > 0) {
    st.message_start_time =
        st.message_count == 0 ? meta.start_time : std::min(st.message_start_time, meta.start_time);
    st.message_end_time =
        st.message_count == 0 ? meta.end_time : std::max(st.message_end_time, meta.end_time);
    st.message_count += count;
    for (const MessageIndex& mi : indexes) st.channel_message_counts[mi.channel_id] += mi.records.size();
  }
  return w.write_chunk(chunk.records, chunk.records, chunk.uncompressed_crc, meta, chunk.uncompressed_size);
}

Status Writer::flush_chunk() {
  if (Status s = impl_->check_open(); !s.ok()) return s;
  if (Status s = impl_->flush_chunk(); !s.ok()) return s;
  return impl_->finish_pending();
}

Status Writer::write_compressed_chunk() {
  if (Status s = impl_->check_open(); !s.ok()) return s;
  return impl_->write_compressed_chunk();
}

Status Writer::close() {
  if (!impl_->open) return Error{"writer is not open", ErrorCode::NotOpen};
  impl_->open = false;
  if (!impl_->error.ok()) {
    impl_->worker.reset();
    (void)impl_->sink->close();
    return impl_->error;
  }
  return impl_->finish();
}

bool Writer::is_open() const {
  return impl_->open;
}
const Statistics& Writer::statistics() const {
  return impl_->stats;
}
const Bytes& Writer::buffer() const {
  static const Bytes kEmpty;
  return impl_->sink ? impl_->sink->buffer() : kEmpty;
}

}  // namespace rbsim::mcap
