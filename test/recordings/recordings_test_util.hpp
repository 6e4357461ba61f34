// Helpers for the log tool tests: recordings made in-process, raw record walks, byte patches that
// keep the file's CRCs valid (so a test sees exactly the problem it planted).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "rbsim/check.hpp"
#include "rbsim/export.hpp"
#include "rbsim/mcap.hpp"
#include "rbsim/mcap_sink.hpp"
#include "rbsim/mcap_tools.hpp"
#include "rbsim/test_bytes.hpp"

namespace rbsim::test {

mcap::Bytes read_bytes(const std::filesystem::path& path);
void write_bytes(const std::filesystem::path& path, const mcap::Bytes& bytes);

std::string source_path(const std::string& relative);  // under the repository root
std::string data_path(const std::string& relative);    // under test/data

// Runs `scene` for `steps` steps in-process and records it (rbsim run --record, with a chosen
// chunk size so small recordings still have many chunks).
// `csv` / `energy_csv`, when not empty, get what rbsim run --csv / --energy-csv write.
struct RecordSpec {
  std::uint64_t chunk_size = 1 << 20;
  std::int64_t every = 1;
  mcap::Compression compression = mcap::Compression::Zstd;
  std::filesystem::path csv, energy_csv;
};
void record_scene(const std::string& scene, const std::filesystem::path& out, std::int64_t steps,
                  const RecordSpec& spec = {});

struct RawRecord {
  std::uint8_t opcode = 0;
  std::uint64_t offset = 0, length = 0;  // whole record
};
// Top-level records of a well-formed file, magic to Footer.
std::vector<RawRecord> top_level_records(const mcap::Bytes& file);
// By value: callers pass top_level_records(...) straight in, a temporary.
RawRecord find_record(const std::vector<RawRecord>& records, mcap::Opcode opcode, std::size_t nth = 0);

// Replaces the record at `at` with `record` (its serialisation must have the same length).
void overwrite_record(mcap::Bytes& file, const RawRecord& at, const mcap::Record& record);
mcap::Record parse_at(const mcap::Bytes& file, const RawRecord& at);

// Recomputes DataEnd.data_section_crc and Footer.summary_crc after a patch.
void fix_crcs(mcap::Bytes& file);

// Messages per chunk, counted from the chunk indexes and the message index records they point at
// (not by reading the chunks).
struct ChunkCount {
  std::uint64_t start = 0, end = 0;  // file offsets of the chunk record
  std::uint64_t messages = 0;
};
std::vector<ChunkCount> chunk_message_counts(const std::filesystem::path& path);

}  // namespace rbsim::test
