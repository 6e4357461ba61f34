#include "record_json.hpp"

#include <algorithm>
#include <fstream>
#include <iterator>
#include <set>

namespace rbsim::mcap::test {
namespace {

using nlohmann::json;
using Fields = std::vector<std::pair<std::string, json>>;

template <typename T>
json num(T v) {
  return std::to_string(static_cast<std::uint64_t>(v));
}
json bytes(const Bytes& b) {
  json a = json::array();
  for (std::byte v : b) a.push_back(num(std::to_integer<unsigned>(v)));
  return a;
}
json string_map(const KeyValueMap& m) {
  json o = json::object();
  for (const auto& [k, v] : m) o[k] = v;
  return o;
}
json id_map(const std::map<std::uint16_t, std::uint64_t>& m) {
  json o = json::object();
  for (const auto& [k, v] : m) o[std::to_string(k)] = num(v);
  return o;
}

Fields fields(const Header& r) {
  return {{"profile", r.profile}, {"library", r.library}};
}
Fields fields(const Footer& r) {
  return {{"summary_start", num(r.summary_start)},
          {"summary_offset_start", num(r.summary_offset_start)},
          {"summary_crc", num(r.summary_crc)}};
}
Fields fields(const Schema& r) {
  return {{"id", num(r.id)}, {"name", r.name}, {"encoding", r.encoding}, {"data", bytes(r.data)}};
}
Fields fields(const Channel& r) {
  return {{"id", num(r.id)},
          {"schema_id", num(r.schema_id)},
          {"topic", r.topic},
          {"message_encoding", r.message_encoding},
          {"metadata", string_map(r.metadata)}};
}
Fields fields(const Message& r) {
  return {{"channel_id", num(r.channel_id)},
          {"sequence", num(r.sequence)},
          {"log_time", num(r.log_time)},
          {"publish_time", num(r.publish_time)},
          {"data", bytes(r.data)}};
}
Fields fields(const Chunk& r) {
  return {{"message_start_time", num(r.message_start_time)},
          {"message_end_time", num(r.message_end_time)},
          {"uncompressed_size", num(r.uncompressed_size)},
          {"uncompressed_crc", num(r.uncompressed_crc)},
          {"compression", r.compression},
          {"records", bytes(r.records)}};
}
Fields fields(const MessageIndex& r) {
  json records = json::array();
  for (const auto& [t, o] : r.records) records.push_back(json::array({num(t), num(o)}));
  return {{"channel_id", num(r.channel_id)}, {"records", records}};
}
Fields fields(const ChunkIndex& r) {
  return {{"message_start_time", num(r.message_start_time)},
          {"message_end_time", num(r.message_end_time)},
          {"chunk_start_offset", num(r.chunk_start_offset)},
          {"chunk_length", num(r.chunk_length)},
          {"message_index_offsets", id_map(r.message_index_offsets)},
          {"message_index_length", num(r.message_index_length)},
          {"compression", r.compression},
          {"compressed_size", num(r.compressed_size)},
          {"uncompressed_size", num(r.uncompressed_size)}};
}
// The suite's Attachment has no crc field (its reference reader checks and drops it).
Fields fields(const Attachment& r) {
  return {{"log_time", num(r.log_time)},
          {"create_time", num(r.create_time)},
          {"name", r.name},
          {"media_type", r.media_type},
          {"data", bytes(r.data)}};
}
Fields fields(const AttachmentIndex& r) {
  return {{"offset", num(r.offset)},           {"length", num(r.length)},       {"log_time", num(r.log_time)},
          {"create_time", num(r.create_time)}, {"data_size", num(r.data_size)}, {"name", r.name},
          {"media_type", r.media_type}};
}
Fields fields(const Statistics& r) {
  return {{"message_count", num(r.message_count)},
          {"schema_count", num(r.schema_count)},
          {"channel_count", num(r.channel_count)},
          {"attachment_count", num(r.attachment_count)},
          {"metadata_count", num(r.metadata_count)},
          {"chunk_count", num(r.chunk_count)},
          {"message_start_time", num(r.message_start_time)},
          {"message_end_time", num(r.message_end_time)},
          {"channel_message_counts", id_map(r.channel_message_counts)}};
}
Fields fields(const Metadata& r) {
  return {{"name", r.name}, {"metadata", string_map(r.metadata)}};
}
Fields fields(const MetadataIndex& r) {
  return {{"offset", num(r.offset)}, {"length", num(r.length)}, {"name", r.name}};
}
Fields fields(const SummaryOffset& r) {
  return {{"group_opcode", num(r.group_opcode)},
          {"group_start", num(r.group_start)},
          {"group_length", num(r.group_length)}};
}
Fields fields(const DataEnd& r) {
  return {{"data_section_crc", num(r.data_section_crc)}};
}
Fields fields(const UnknownRecord& r) {
  return {{"opcode", num(r.opcode)}, {"data", bytes(r.data)}};
}

std::uint64_t field_u64(const json& record, const char* name) {
  for (const auto& f : record["fields"]) {
    if (f[0] == name) return std::stoull(f[1].get<std::string>());
  }
  return 0;
}

}  // namespace

json record_to_json(const Record& record) {
  Fields f = std::visit([](const auto& r) { return fields(r); }, record);
  std::sort(f.begin(), f.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  json out_fields = json::array();
  for (auto& [name, value] : f) out_fields.push_back(json::array({name, std::move(value)}));
  return json{{"type", std::string(record_type_name(record))}, {"fields", std::move(out_fields)}};
}

json indexed_view_of(const json& records) {
  json schemas = json::array(), channels = json::array(), messages = json::array(), stats = json::array();
  std::set<std::uint64_t> schema_ids, channel_ids;
  for (const json& r : records) {
    const std::string type = r["type"];
    if (type == "Schema" && schema_ids.insert(field_u64(r, "id")).second) schemas.push_back(r);
    if (type == "Channel" && channel_ids.insert(field_u64(r, "id")).second) channels.push_back(r);
    if (type == "Message") messages.push_back(r);
    if (type == "Statistics") stats.push_back(r);
  }
  auto by = [](const char* name) {
    return [name](const json& a, const json& b) { return field_u64(a, name) < field_u64(b, name); };
  };
  std::stable_sort(messages.begin(), messages.end(), by("log_time"));
  std::stable_sort(schemas.begin(), schemas.end(), by("id"));
  std::stable_sort(channels.begin(), channels.end(), by("id"));
  return json{{"schemas", schemas}, {"channels", channels}, {"messages", messages}, {"statistics", stats}};
}

Bytes read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return bytes_of(std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()));
}

}  // namespace rbsim::mcap::test
