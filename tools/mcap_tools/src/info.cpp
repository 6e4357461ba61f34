// rbsim log info: what `mcap info` shows, from the summary when the file has one (else a scan).
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "rbsim/mcap_tools.hpp"
#include "tools_util.hpp"

namespace rbsim::mcap_tools {

namespace {

Error fail(const Status& s) {
  return Error{read_error(s.error())};
}

CompressionStats& stats_for(std::vector<CompressionStats>& v, const std::string& name) {
  for (CompressionStats& s : v) {
    if (s.compression == name) return s;
  }
  v.push_back(CompressionStats{name, 0, 0, 0});
  return v.back();
}

void fill_channels(LogInfo& info, const std::map<std::uint16_t, mcap::Channel>& channels,
                   const std::map<std::uint16_t, mcap::Schema>& schemas,
                   const std::map<std::uint16_t, std::uint64_t>& counts) {
  for (const auto& [id, channel] : channels) {
    ChannelSummary c;
    c.channel = channel;
    const auto n = counts.find(id);
    c.messages = n == counts.end() ? 0 : n->second;
    if (channel.schema_id != 0) {
      const auto s = schemas.find(channel.schema_id);
      if (s == schemas.end()) {
        c.schema_missing = true;
      } else {
        c.schema_name = s->second.name;
        c.schema_encoding = s->second.encoding;
      }
    }
    info.channels.push_back(std::move(c));
  }
  info.schemas = schemas.size();
}

// Every record in order: for files without a usable summary.
Result<LogInfo> scan(const std::string& path, LogInfo info) {
  mcap::StreamReader reader;
  mcap::StreamOptions so;
  so.report_chunks = true;
  if (Status s = reader.open(path, so); !s.ok()) return fail(s);
  std::map<std::uint16_t, mcap::Schema> schemas;
  std::map<std::uint16_t, mcap::Channel> channels;
  std::map<std::uint16_t, std::uint64_t> counts;
  info.scanned = true;
  info.messages = info.chunks = info.attachment_count = info.metadata_count = 0;
  info.compression.clear();
  info.attachments.clear();
  info.metadata.clear();
  bool in_summary = false;
  mcap::RecordEntry e;
  while (reader.next(e)) {
    if (std::holds_alternative<mcap::DataEnd>(e.record)) in_summary = true;
    if (in_summary) continue;  // the summary repeats what the data section holds
    if (auto* m = std::get_if<mcap::Message>(&e.record)) {
      info.start = info.messages == 0 ? m->log_time : std::min(info.start, m->log_time);
      info.end = info.messages == 0 ? m->log_time : std::max(info.end, m->log_time);
      ++info.messages;
      ++counts[m->channel_id];
    } else if (auto* c = std::get_if<mcap::Chunk>(&e.record)) {
      CompressionStats& cs = stats_for(info.compression, c->compression);
      ++cs.chunks;
      cs.compressed_bytes += c->records.size();
      cs.uncompressed_bytes += c->uncompressed_size;
      ++info.chunks;
    } else if (auto* s = std::get_if<mcap::Schema>(&e.record)) {
      schemas.try_emplace(s->id, std::move(*s));
    } else if (auto* ch = std::get_if<mcap::Channel>(&e.record)) {
      channels.try_emplace(ch->id, std::move(*ch));
    } else if (auto* a = std::get_if<mcap::Attachment>(&e.record)) {
      info.attachments.push_back(mcap::AttachmentIndex{e.offset, e.length, a->log_time, a->create_time,
                                                       a->data.size(), a->name, a->media_type});
      ++info.attachment_count;
    } else if (auto* md = std::get_if<mcap::Metadata>(&e.record)) {
      info.metadata.push_back(md->name);
      ++info.metadata_count;
    }
  }
  if (!reader.status().ok()) return fail(reader.status());
  fill_channels(info, channels, schemas, counts);
  return info;
}

std::string human_bytes(std::uint64_t n) {
  static constexpr const char* kUnits[] = {"B", "KiB", "MiB", "GiB", "TiB"};
  double v = static_cast<double>(n);
  std::size_t u = 0;
  while (v > 1024 && u + 1 < std::size(kUnits)) {
    v /= 1024;
    ++u;
  }
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.2f %s", v, kUnits[u]);
  return buf;
}

}  // namespace

Result<LogInfo> info(const std::string& path) {
  LogInfo info;
  {
    auto source = detail::open_input(path);
    if (!source) return source.error();
    info.file_size = source.value()->size();
    if (info.file_size == 0) return Error{"empty file (0 bytes): not an MCAP file"};
  }
  mcap::IndexedReader reader;
  if (Status s = reader.open(path); !s.ok()) return fail(s);
  // The summary says nothing about a byte flipped in a chunk: the data section CRC does.
  if (Status s = reader.verify_data_section_crc(); !s.ok()) return fail(s);
  info.header = reader.header();
  const auto& stats = reader.statistics();
  if (!stats) {
    info.scan_reason =
        reader.footer().summary_start == 0 ? "the file has no summary" : "the summary has no statistics";
    return scan(path, std::move(info));
  }
  if (stats->chunk_count != 0 && reader.chunk_indexes().size() != stats->chunk_count) {
    info.scan_reason = "the summary lacks chunk indexes";
    return scan(path, std::move(info));
  }
  info.messages = stats->message_count;
  info.start = stats->message_start_time;
  info.end = stats->message_end_time;
  info.chunks = stats->chunk_count;
  for (const mcap::ChunkIndex& ci : reader.chunk_indexes()) {
    CompressionStats& cs = stats_for(info.compression, ci.compression);
    ++cs.chunks;
    cs.compressed_bytes += ci.compressed_size;
    cs.uncompressed_bytes += ci.uncompressed_size;
  }
  info.attachment_count = stats->attachment_count;
  info.metadata_count = stats->metadata_count;
  info.attachments = reader.attachment_indexes();
  for (const mcap::MetadataIndex& mi : reader.metadata_indexes()) info.metadata.push_back(mi.name);
  // Channels and schemas: the summary repeats them in rbsim logs; others may keep them only in
  // chunks, which the indexed reader learns while reading messages.
  std::map<std::uint16_t, mcap::Channel> channels = reader.channels();
  std::map<std::uint16_t, mcap::Schema> schemas = reader.schemas();
  if (channels.size() < stats->channel_count) {
    if (Status s = reader.read_messages({}, [](const mcap::MessageEntry&) { return true; }); !s.ok()) {
      return fail(s);
    }
    channels = reader.channels();
    schemas = reader.schemas();
  }
  fill_channels(info, channels, schemas, stats->channel_message_counts);
  return info;
}

std::string format_info(const LogInfo& info) {
  std::string out;
  char buf[256];
  auto line = [&](const char* key, const std::string& value) {
    std::snprintf(buf, sizeof buf, "%-13s%s\n", key, value.c_str());
    out += buf;
  };
  line("library:", info.header.library);
  line("profile:", info.header.profile);
  line("file size:", std::to_string(info.file_size) + " bytes (" + human_bytes(info.file_size) + ")");
  if (info.scanned)
    line("summary:", "none usable (" + info.scan_reason + "): counts from a scan of the whole file");
  line("messages:", std::to_string(info.messages));
  const std::uint64_t span = info.end >= info.start ? info.end - info.start : 0;
  const double duration = static_cast<double>(span) / 1e9;
  if (info.messages > 0) {
    line("duration:", seconds(span) + " s");
    line("start:", seconds(info.start) + " s");
    line("end:", seconds(info.end) + " s");
  }
  line("chunks:", std::to_string(info.chunks));
  if (!info.compression.empty()) {
    out += "compression:\n";
    for (const CompressionStats& c : info.compression) {
      const double saved = c.uncompressed_bytes == 0
                               ? 0.0
                               : 100.0 * (1.0 - static_cast<double>(c.compressed_bytes) /
                                                    static_cast<double>(c.uncompressed_bytes));
      const double ratio = c.compressed_bytes == 0 ? 0.0
                                                   : static_cast<double>(c.uncompressed_bytes) /
                                                         static_cast<double>(c.compressed_bytes);
      std::snprintf(buf, sizeof buf, "\t%s: [%llu/%llu chunks] [%s/%s (%.2f%% smaller, ratio %.2f)]",
                    c.compression.empty() ? "none" : c.compression.c_str(),
                    static_cast<unsigned long long>(c.chunks), static_cast<unsigned long long>(info.chunks),
                    human_bytes(c.uncompressed_bytes).c_str(), human_bytes(c.compressed_bytes).c_str(), saved,
                    ratio);
      out += buf;
      if (duration > 0) {
        out += " [" +
               human_bytes(static_cast<std::uint64_t>(static_cast<double>(c.compressed_bytes) / duration)) +
               "/sec]";
      }
      out += '\n';
    }
  }
  out += "channels:\n";
  struct Row {
    std::string id, topic, count, schema;
  };
  std::vector<Row> rows;
  std::size_t widths[3] = {0, 0, 0};
  for (const ChannelSummary& c : info.channels) {
    Row r;
    r.id = "(" + std::to_string(c.channel.id) + ")";
    r.topic = c.channel.topic;
    r.count = std::to_string(c.messages) + " msgs";
    if (span > 0) {
      std::snprintf(buf, sizeof buf, " (%.2f Hz)",
                    1e9 * static_cast<double>(c.messages) / static_cast<double>(span));
      r.count += buf;
    }
    if (c.schema_missing) {
      r.schema = "<missing schema " + std::to_string(c.channel.schema_id) + ">";
    } else if (c.channel.schema_id == 0) {
      r.schema = "<no schema>";
    } else {
      r.schema = c.schema_name + " [" + c.schema_encoding + "]";
    }
    r.schema +=
        ", " + (c.channel.message_encoding.empty() ? std::string("no encoding") : c.channel.message_encoding);
    widths[0] = std::max(widths[0], r.id.size());
    widths[1] = std::max(widths[1], r.topic.size());
    widths[2] = std::max(widths[2], r.count.size());
    rows.push_back(std::move(r));
  }
  for (const Row& r : rows) {
    std::snprintf(buf, sizeof buf, "\t%-*s %-*s  %-*s : ", static_cast<int>(widths[0]), r.id.c_str(),
                  static_cast<int>(widths[1]), r.topic.c_str(), static_cast<int>(widths[2]), r.count.c_str());
    out += buf + r.schema + "\n";
  }
  out += "attachments: " + std::to_string(info.attachment_count) + "\n";
  for (const mcap::AttachmentIndex& a : info.attachments) {
    out += "\t" + a.name + " [" + a.media_type + "] " + std::to_string(a.data_size) + " bytes\n";
  }
  out += "metadata: " + std::to_string(info.metadata_count) + "\n";
  for (const std::string& m : info.metadata) out += "\t" + m + "\n";
  return out;
}

}  // namespace rbsim::mcap_tools
