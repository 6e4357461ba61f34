#include "conformance_gen.hpp"

#include <array>
#include <cstdio>
#include <set>

namespace rbsim::mcap::test {
namespace {

using nlohmann::json;

const json& field(const json& record, const char* name) {
  for (const auto& f : record["fields"]) {
    if (f[0] == name) return f[1];
  }
  static const json kNull;
  return kNull;
}
std::uint64_t u64(const json& record, const char* name) {
  return std::stoull(field(record, name).get<std::string>());
}
template <typename T>
T as(const json& record, const char* name) {
  return static_cast<T>(u64(record, name));
}
std::string str(const json& record, const char* name) {
  return field(record, name).get<std::string>();
}
Bytes bytes(const json& record, const char* name) {
  Bytes out;
  for (const auto& v : field(record, name))
    out.push_back(static_cast<std::byte>(std::stoul(v.get<std::string>())));
  return out;
}
KeyValueMap string_map(const json& record, const char* name) {
  KeyValueMap out;
  for (const auto& [k, v] : field(record, name).items()) out[k] = v.get<std::string>();
  return out;
}

class Builder {
 public:
  explicit Builder(bool pad) : pad_(pad) {}
  Bytes out;

  // McapRecordBuilder pads every record with 01 FF FF except Footer, Message, Chunk and DataEnd.
  std::uint64_t write(const Record& record) {
    const std::size_t start = out.size();
    serialize_record(record, out);
    const bool paddable = !std::holds_alternative<Message>(record) &&
                          !std::holds_alternative<Chunk>(record) &&
                          !std::holds_alternative<DataEnd>(record) && !std::holds_alternative<Footer>(record);
    if (std::holds_alternative<Attachment>(record)) {
      const std::uint32_t crc = crc32(ByteView(out).subspan(start + 9, out.size() - start - 9 - 4));
      for (std::size_t i = 0; i < 4; ++i) out[out.size() - 4 + i] = static_cast<std::byte>(crc >> (8 * i));
    }
    if (pad_ && paddable) {
      out.insert(out.end(), {std::byte{0x01}, std::byte{0xFF}, std::byte{0xFF}});
      const std::uint64_t length = out.size() - start - 9;
      for (std::size_t i = 0; i < 8; ++i) out[start + 1 + i] = static_cast<std::byte>(length >> (8 * i));
    }
    return out.size() - start;
  }

 private:
  bool pad_;
};

}  // namespace

Bytes generate_conformance_file(const json& expected) {
  std::set<std::string> features;
  for (const auto& f : expected["meta"]["variant"]["features"]) features.insert(f.get<std::string>());
  auto has = [&](const char* f) { return features.count(f) > 0; };
  // The test input is every data record before DataEnd (summary copies come after it).
  std::vector<json> inputs;
  for (const auto& r : expected["records"]) {
    if (r["type"] == "DataEnd") break;
    if (r["type"] != "Header") inputs.push_back(r);
  }

  Builder b(has("pad"));
  b.out.assign(std::begin(kMagic), std::end(kMagic));
  b.write(Header{"", ""});

  const bool chunked = has("ch");
  Builder chunk(false);               // ChunkBuilder's own record builder never pads
  std::vector<MessageIndex> indices;  // insertion order, like the JS Map
  auto index_for = [&](std::uint16_t channel) -> MessageIndex& {
    for (auto& mi : indices) {
      if (mi.channel_id == channel) return mi;
    }
    indices.push_back({channel, {}});
    return indices.back();
  };
  Statistics stats;
  std::vector<std::pair<std::uint16_t, std::uint64_t>> channel_counts;
  std::vector<AttachmentIndex> attachment_indexes;
  std::vector<MetadataIndex> metadata_indexes;
  std::vector<Schema> schemas;
  std::vector<Channel> channels;
  for (const json& r : inputs) {
    const std::string type = r["type"];
    if (type == "Schema") {
      schemas.push_back({as<std::uint16_t>(r, "id"), str(r, "name"), str(r, "encoding"), bytes(r, "data")});
      ++stats.schema_count;
      (chunked ? chunk : b).write(schemas.back());
    } else if (type == "Channel") {
      channels.push_back({as<std::uint16_t>(r, "id"), as<std::uint16_t>(r, "schema_id"), str(r, "topic"),
                          str(r, "message_encoding"), string_map(r, "metadata")});
      ++stats.channel_count;
      if (chunked && has("mx")) index_for(channels.back().id);
      (chunked ? chunk : b).write(channels.back());
    } else if (type == "Message") {
      Message m{as<std::uint16_t>(r, "channel_id"), as<std::uint32_t>(r, "sequence"), u64(r, "log_time"),
                u64(r, "publish_time"), bytes(r, "data")};
      const bool first = stats.message_count++ == 0;
      stats.message_start_time = first ? m.log_time : std::min(stats.message_start_time, m.log_time);
      stats.message_end_time = first ? m.log_time : std::max(stats.message_end_time, m.log_time);
      bool counted = false;
      for (auto& [id, n] : channel_counts) counted = id == m.channel_id ? (++n, true) : counted;
      if (!counted) channel_counts.emplace_back(m.channel_id, 1);
      if (chunked && has("mx")) index_for(m.channel_id).records.emplace_back(m.log_time, chunk.out.size());
      (chunked ? chunk : b).write(m);
    } else if (type == "Attachment") {
      ++stats.attachment_count;
      Attachment a{u64(r, "log_time"),   u64(r, "create_time"), str(r, "name"),
                   str(r, "media_type"), bytes(r, "data"),      0};
      const std::uint64_t offset = b.out.size();
      const std::uint64_t length = b.write(a);
      if (has("ax")) {
        attachment_indexes.push_back(
            {offset, length, a.log_time, a.create_time, a.data.size(), a.name, a.media_type});
      }
    } else if (type == "Metadata") {
      ++stats.metadata_count;
      const std::uint64_t offset = b.out.size();
      const std::uint64_t length = b.write(Metadata{str(r, "name"), string_map(r, "metadata")});
      if (has("mdx")) metadata_indexes.push_back({offset, length, str(r, "name")});
    }
  }
  for (const auto& [id, n] : channel_counts) stats.channel_message_counts[id] = n;

  std::vector<ChunkIndex> chunk_indexes;
  if (chunked) {
    stats.chunk_count = 1;
    const bool any = stats.message_count > 0;
    ChunkIndex ci;
    ci.message_start_time = any ? stats.message_start_time : 0;
    ci.message_end_time = any ? stats.message_end_time : 0;
    ci.chunk_start_offset = b.out.size();
    ci.chunk_length = b.write(
        Chunk{ci.message_start_time, ci.message_end_time, chunk.out.size(), crc32(chunk.out), "", chunk.out});
    for (auto& mi : indices) {
      ci.message_index_offsets[mi.channel_id] = b.out.size();
      ci.message_index_length += b.write(mi);
    }
    ci.compressed_size = ci.uncompressed_size = chunk.out.size();
    if (has("chx")) chunk_indexes.push_back(ci);
  }
  b.write(DataEnd{crc32(b.out)});

  const std::uint64_t summary_start = b.out.size();
  std::vector<SummaryOffset> groups;
  auto group = [&](Opcode op, const auto& records) {
    const std::uint64_t start = b.out.size();
    for (const auto& rec : records) b.write(rec);
    if (b.out.size() != start) groups.push_back({static_cast<std::uint8_t>(op), start, b.out.size() - start});
  };
  group(Opcode::Schema, has("rsh") ? schemas : std::vector<Schema>{});
  group(Opcode::Channel, has("rch") ? channels : std::vector<Channel>{});
  group(Opcode::Statistics, has("st") ? std::vector<Statistics>{stats} : std::vector<Statistics>{});
  group(Opcode::MetadataIndex, metadata_indexes);
  group(Opcode::AttachmentIndex, attachment_indexes);
  group(Opcode::ChunkIndex, chunk_indexes);
  const bool has_summary = b.out.size() != summary_start;
  Footer footer{has_summary ? summary_start : 0, 0, 0};
  if (has("sum")) {
    footer.summary_offset_start = b.out.size();
    for (const auto& g : groups) b.write(g);
  }
  // Summary CRC: from the end of DataEnd through Footer.summary_offset_start.
  Bytes tail(b.out.begin() + static_cast<std::ptrdiff_t>(summary_start), b.out.end());
  serialize_record(footer, tail);
  footer.summary_crc = crc32(ByteView(tail).first(tail.size() - 4));
  b.write(footer);
  b.out.insert(b.out.end(), std::begin(kMagic), std::end(kMagic));
  return b.out;
}

std::string sha256_hex(ByteView data) {
  static constexpr std::array<std::uint32_t, 64> k = {
      0x428a2f98, 0x71374491, 0xb5c0fbcf, 0xe9b5dba5, 0x3956c25b, 0x59f111f1, 0x923f82a4, 0xab1c5ed5,
      0xd807aa98, 0x12835b01, 0x243185be, 0x550c7dc3, 0x72be5d74, 0x80deb1fe, 0x9bdc06a7, 0xc19bf174,
      0xe49b69c1, 0xefbe4786, 0x0fc19dc6, 0x240ca1cc, 0x2de92c6f, 0x4a7484aa, 0x5cb0a9dc, 0x76f988da,
      0x983e5152, 0xa831c66d, 0xb00327c8, 0xbf597fc7, 0xc6e00bf3, 0xd5a79147, 0x06ca6351, 0x14292967,
      0x27b70a85, 0x2e1b2138, 0x4d2c6dfc, 0x53380d13, 0x650a7354, 0x766a0abb, 0x81c2c92e, 0x92722c85,
      0xa2bfe8a1, 0xa81a664b, 0xc24b8b70, 0xc76c51a3, 0xd192e819, 0xd6990624, 0xf40e3585, 0x106aa070,
      0x19a4c116, 0x1e376c08, 0x2748774c, 0x34b0bcb5, 0x391c0cb3, 0x4ed8aa4a, 0x5b9cca4f, 0x682e6ff3,
      0x748f82ee, 0x78a5636f, 0x84c87814, 0x8cc70208, 0x90befffa, 0xa4506ceb, 0xbef9a3f7, 0xc67178f2};
  std::array<std::uint32_t, 8> h = {0x6a09e667, 0xbb67ae85, 0x3c6ef372, 0xa54ff53a,
                                    0x510e527f, 0x9b05688c, 0x1f83d9ab, 0x5be0cd19};
  Bytes msg(data.begin(), data.end());
  const std::uint64_t bits = static_cast<std::uint64_t>(data.size()) * 8;
  msg.push_back(std::byte{0x80});
  while (msg.size() % 64 != 56) msg.push_back(std::byte{0});
  for (int i = 7; i >= 0; --i) msg.push_back(static_cast<std::byte>(bits >> (8 * i)));
  auto rotr = [](std::uint32_t x, int n) { return (x >> n) | (x << (32 - n)); };
  for (std::size_t block = 0; block < msg.size(); block += 64) {
    std::array<std::uint32_t, 64> w{};
    for (std::size_t i = 0; i < 16; ++i) {
      const std::byte* p = &msg[block + 4 * i];
      w[i] = std::to_integer<std::uint32_t>(p[0]) << 24 | std::to_integer<std::uint32_t>(p[1]) << 16 |
             std::to_integer<std::uint32_t>(p[2]) << 8 | std::to_integer<std::uint32_t>(p[3]);
    }
    for (std::size_t i = 16; i < 64; ++i) {
      const std::uint32_t s0 = rotr(w[i - 15], 7) ^ rotr(w[i - 15], 18) ^ (w[i - 15] >> 3);
      const std::uint32_t s1 = rotr(w[i - 2], 17) ^ rotr(w[i - 2], 19) ^ (w[i - 2] >> 10);
      w[i] = w[i - 16] + s0 + w[i - 7] + s1;
    }
    std::array<std::uint32_t, 8> v = h;
    for (std::size_t i = 0; i < 64; ++i) {
      const std::uint32_t s1 = rotr(v[4], 6) ^ rotr(v[4], 11) ^ rotr(v[4], 25);
      const std::uint32_t ch = (v[4] & v[5]) ^ (~v[4] & v[6]);
      const std::uint32_t t1 = v[7] + s1 + ch + k[i] + w[i];
      const std::uint32_t s0 = rotr(v[0], 2) ^ rotr(v[0], 13) ^ rotr(v[0], 22);
      const std::uint32_t maj = (v[0] & v[1]) ^ (v[0] & v[2]) ^ (v[1] & v[2]);
      const std::uint32_t t2 = s0 + maj;
      v = {t1 + t2, v[0], v[1], v[2], v[3] + t1, v[4], v[5], v[6]};
    }
    for (std::size_t i = 0; i < 8; ++i) h[i] += v[i];
  }
  std::string hex;
  char buf[9];
  for (std::uint32_t x : h) {
    std::snprintf(buf, sizeof buf, "%08x", x);
    hex += buf;
  }
  return hex;
}

}  // namespace rbsim::mcap::test
