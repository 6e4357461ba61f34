// rbsim log doctor, the chunk examination: decompression and CRC, the records inside a chunk, and
// its MessageIndex records against the messages they point at (both ways).
#include <algorithm>
#include <unordered_map>

#include "doctor.hpp"

namespace rbsim::mcap_tools::detail {

using mcap::opcode_name;
using mcap::opcode_of;

struct ChunkScan {
  ChunkScan(const mcap::Chunk& c, ChunkInfo& i, std::string w) : chunk(c), info(i), where(std::move(w)) {}
  const mcap::Chunk& chunk;
  ChunkInfo& info;
  std::string where;
  // Message index entries by channel: offset -> log time.
  std::map<std::uint16_t, std::unordered_map<std::uint64_t, mcap::Timestamp>> index_entries;
  std::unordered_map<std::uint64_t, std::uint16_t> message_at;  // offset -> channel
  mcap::Timestamp min_time = mcap::kMaxTime, max_time = 0;
  std::uint64_t count = 0;
};

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
  ChunkScan scan(chunk, info, cat("Chunk at offset ", p.offset));

  mcap::Bytes data;
  if (!decompress(chunk, scan.where, data)) return;
  for (const auto& [channel_id, mi] : p.indexes) {
    auto& entries = scan.index_entries[channel_id];
    for (const auto& [t, offset] : mi.records) entries.emplace(offset, t);
  }
  mcap::ViewSource records(data);
  mcap::RecordReader reader(records);
  reader.on_problem([&](const mcap::RecordProblem& problem) {
    if (!problem.content_length) {
      error(cat(scan.where, ": record header cut off at byte ", problem.offset,
                " of the uncompressed records"));
    } else {
      error(cat(scan.where, ": ", opcode_name(*problem.opcode), " record at byte ", problem.offset,
                " claims ", *problem.content_length, " bytes, only ",
                problem.available - mcap::RecordReader::kPrefixSize, " remain in the chunk"));
    }
  });
  mcap::RecordView record;
  while (reader.next(record)) {
    const std::uint8_t opcode = record.opcode;
    if (opcode != opcode_of<mcap::Schema>() && opcode != opcode_of<mcap::Channel>() &&
        opcode != opcode_of<mcap::Message>()) {
      error(cat(scan.where, ": Illegal record in chunk: ", opcode_name(opcode), " at byte ", record.offset));
      continue;
    }
    auto parsed = mcap::parse_record(opcode, record.content);
    if (!parsed.ok()) {
      error(cat(scan.where, ": failed to parse ", opcode_name(opcode), " at byte ", record.offset, ": ",
                parsed.error().message));
    } else if (const auto* schema = std::get_if<mcap::Schema>(&parsed.value())) {
      examine_schema(*schema);
    } else if (const auto* channel = std::get_if<mcap::Channel>(&parsed.value())) {
      examine_channel(*channel);
    } else {
      examine_chunk_message(scan, record.offset, std::get<mcap::Message>(parsed.value()));
    }
  }
  check_index_entries(scan);
  if (scan.count != 0) {
    if (scan.min_time != chunk.message_start_time) {
      error(cat("Chunk.message_start_time ", chunk.message_start_time,
                " does not match the earliest message log time ", scan.min_time, " (", scan.where, ")"));
    }
    if (scan.max_time != chunk.message_end_time) {
      error(cat("Chunk.message_end_time ", chunk.message_end_time,
                " does not match the latest message log time ", scan.max_time, " (", scan.where, ")"));
    }
    min_log_time_ = std::min(min_log_time_, scan.min_time);
  }
}

// The chunk's records into `data`; false (reported) when they cannot be had or fail the CRC.
bool Doctor::decompress(const mcap::Chunk& chunk, const std::string& where, mcap::Bytes& data) {
  if (Status s = mcap::decompress_chunk(chunk, data, false); !s.ok()) {
    if (s.code() == ErrorCode::UnsupportedCompression) {
      error(cat(where, ": Unsupported compression format: \"", chunk.compression, "\""));
    } else if (s.code() == ErrorCode::Malformed) {
      error(
          cat(where, ": Uncompressed chunk data size != Chunk.uncompressed_size (", s.error().message, ")"));
    } else {
      error(cat(where, ": Could not decompress: ", s.error().message));
    }
    return false;
  }
  if (chunk.uncompressed_crc != 0) {
    const std::uint32_t crc = mcap::crc32(data);
    if (crc != chunk.uncompressed_crc) {
      error(cat(where, ": invalid CRC: computed ", hex32(crc), ", Chunk.uncompressed_crc is ",
                hex32(chunk.uncompressed_crc)));
      return false;
    }
  }
  return true;
}

// A message at `offset` of the chunk's records: its channel, order and index entry.
void Doctor::examine_chunk_message(ChunkScan& scan, std::uint64_t offset, const mcap::Message& m) {
  const std::string& where = scan.where;
  scan.info.channels.insert(m.channel_id);
  scan.message_at.emplace(offset, m.channel_id);
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
  scan.min_time = std::min(scan.min_time, m.log_time);
  scan.max_time = std::max(scan.max_time, m.log_time);
  max_log_time_ = std::max(max_log_time_, m.log_time);
  ++scan.count;
  ++message_count_;
  ++channel_message_counts_[m.channel_id];
  const auto idx = scan.index_entries.find(m.channel_id);
  if (idx == scan.index_entries.end()) {
    warn(cat(where, ": No MessageIndex record found for channel ", m.channel_id));
    return;
  }
  const auto entry = idx->second.find(offset);
  if (entry == idx->second.end()) {
    warn(cat("No MessageIndex entry found for message channel ", m.channel_id, " with log time ", m.log_time,
             " at offset ", offset, " (", where, ")"));
  } else if (entry->second != m.log_time) {
    error(cat("MessageIndex entry for channel ", m.channel_id, " at offset ", offset, " has timestamp ",
              entry->second, ", but message has timestamp ", m.log_time, " (", where, ")"));
  }
}

// The other direction: every index entry names a message of its channel.
void Doctor::check_index_entries(const ChunkScan& scan) {
  for (const auto& [channel_id, entries] : scan.index_entries) {
    std::vector<std::uint64_t> offsets;
    for (const auto& [offset, t] : entries) offsets.push_back(offset);
    std::sort(offsets.begin(), offsets.end());
    for (std::uint64_t offset : offsets) {
      const auto m = scan.message_at.find(offset);
      if (m == scan.message_at.end()) {
        error(cat("MessageIndex for channel ", channel_id, " (", scan.where, ") has an entry at offset ",
                  offset, " where there is no Message record"));
      } else if (m->second != channel_id) {
        error(cat("MessageIndex for channel ", channel_id, " (", scan.where, ") has an entry at offset ",
                  offset, " that points at a message of channel ", m->second));
      }
    }
  }
}

}  // namespace rbsim::mcap_tools::detail
