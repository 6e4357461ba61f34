#include "recordings_test_util.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <stdexcept>

#include "rbsim/core.hpp"
#include "rbsim/scene.hpp"

namespace rbsim::test {

namespace fs = std::filesystem;

mcap::Bytes read_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return bytes_of(std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()));
}

void write_bytes(const fs::path& path, const mcap::Bytes& bytes) {
  std::error_code ec;
  fs::remove(path, ec);  // a fresh file: truncating one in place is slow on some file systems
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  if (!out) throw std::runtime_error("cannot write " + path.string());
}

std::string source_path(const std::string& relative) {
  return std::string(RBSIM_SOURCE_DIR) + "/" + relative;
}
std::string data_path(const std::string& relative) {
  return std::string(RBSIM_TEST_DATA_DIR) + "/" + relative;
}

void record_scene(const std::string& scene_path, const fs::path& out, std::int64_t steps,
                  const RecordSpec& spec) {
  Result<Scene> scene = load_scene(scene_path);
  ASSERT_TRUE(scene.ok()) << scene.error().message;
  Result<World> world = World::create(scene.value().world);
  ASSERT_TRUE(world.ok()) << world.error().message;
  recordings::McapSinkOptions o;
  o.chunk_size = spec.chunk_size;
  o.every = spec.every;
  o.compression = spec.compression;
  std::vector<std::unique_ptr<Sink>> sinks;
  sinks.push_back(recordings::make_mcap_sink(out.string(), o));
  if (!spec.csv.empty()) sinks.push_back(make_csv_sink(spec.csv.string()));
  if (!spec.energy_csv.empty()) sinks.push_back(make_energy_csv_sink(spec.energy_csv.string()));
  for (auto& sink : sinks) {
    Status st = sink->begin(scene.value(), world.value());
    ASSERT_TRUE(st.ok()) << st.error().message;
  }
  while (world.value().step_index() < steps) {
    world.value().step();
    for (auto& sink : sinks) {
      Status st = sink->write(world.value());
      ASSERT_TRUE(st.ok()) << st.error().message;
    }
  }
  for (auto& sink : sinks) {
    Status st = sink->finish();
    ASSERT_TRUE(st.ok()) << st.error().message;
  }
}

namespace {
std::uint64_t le64(const std::byte* p) {
  std::uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = (v << 8) | std::to_integer<std::uint64_t>(p[i]);
  return v;
}
void put32(std::byte* p, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<std::byte>(v >> (8 * i));
}
}  // namespace

std::vector<RawRecord> top_level_records(const mcap::Bytes& file) {
  std::vector<RawRecord> out;
  for (std::uint64_t pos = 8; pos + 9 <= file.size();) {
    const RawRecord r{std::to_integer<std::uint8_t>(file[pos]), pos, 9 + le64(&file[pos + 1])};
    if (r.length > file.size() - pos) break;
    out.push_back(r);
    pos += r.length;
    if (r.opcode == static_cast<std::uint8_t>(mcap::Opcode::Footer)) break;
  }
  return out;
}

RawRecord find_record(const std::vector<RawRecord>& records, mcap::Opcode opcode, std::size_t nth) {
  for (const RawRecord& r : records) {
    if (r.opcode == static_cast<std::uint8_t>(opcode) && nth-- == 0) return r;
  }
  throw std::runtime_error("no such record");
}

mcap::Record parse_at(const mcap::Bytes& file, const RawRecord& at) {
  auto r = mcap::parse_record(at.opcode, mcap::ByteView(file).subspan(at.offset + 9, at.length - 9));
  if (!r.ok()) throw std::runtime_error(r.error().message);
  return std::move(r).value();
}

void overwrite_record(mcap::Bytes& file, const RawRecord& at, const mcap::Record& record) {
  mcap::Bytes bytes;
  mcap::serialize_record(record, bytes);
  if (bytes.size() != at.length) throw std::runtime_error("patched record changes length");
  std::copy(bytes.begin(), bytes.end(), file.begin() + static_cast<std::ptrdiff_t>(at.offset));
}

void fix_crcs(mcap::Bytes& file) {
  const auto records = top_level_records(file);
  const RawRecord& data_end = find_record(records, mcap::Opcode::DataEnd);
  const RawRecord& footer = find_record(records, mcap::Opcode::Footer);
  put32(&file[data_end.offset + 9], mcap::crc32(mcap::ByteView(file).subspan(0, data_end.offset)));
  const std::uint64_t begin = data_end.offset + data_end.length;
  const std::uint64_t end = footer.offset + 9 + 16;
  put32(&file[footer.offset + 9 + 16], mcap::crc32(mcap::ByteView(file).subspan(begin, end - begin)));
}

std::vector<ChunkCount> chunk_message_counts(const fs::path& path) {
  std::vector<ChunkCount> out;
  mcap::IndexedReader reader;
  EXPECT_TRUE(reader.open(path.string()).ok());
  const mcap::Bytes file = read_bytes(path);
  for (const mcap::ChunkIndex& ci : reader.chunk_indexes()) {
    ChunkCount c{ci.chunk_start_offset, ci.chunk_start_offset + ci.chunk_length, 0};
    for (const auto& [channel, offset] : ci.message_index_offsets) {
      const RawRecord at{std::to_integer<std::uint8_t>(file[offset]), offset, 9 + le64(&file[offset + 1])};
      const auto mi = std::get<mcap::MessageIndex>(parse_at(file, at));
      EXPECT_EQ(mi.channel_id, channel);
      c.messages += mi.records.size();
    }
    out.push_back(c);
  }
  return out;
}

}  // namespace rbsim::test
