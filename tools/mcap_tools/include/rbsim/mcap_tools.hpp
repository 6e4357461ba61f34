// Generic MCAP tools, as the MCAP CLI has them beside its library: `rbsim log info | doctor |
// recover`. They know nothing of rbsim's messages. No input crashes or hangs them: every loop is
// bounded by the bytes read.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "rbsim/mcap.hpp"
#include "rbsim/status.hpp"

namespace rbsim::mcap_tools {

// info ----------------------------------------------------------------------------------------
struct CompressionStats {
  std::string compression;  // "" (none), "zstd", "lz4"
  std::uint64_t chunks = 0, compressed_bytes = 0, uncompressed_bytes = 0;
};
struct ChannelSummary {
  mcap::Channel channel;
  std::uint64_t messages = 0;
  std::string schema_name, schema_encoding;  // empty: schemaless (or schema missing)
  bool schema_missing = false;               // schema_id != 0 but no such Schema record
};
struct LogInfo {
  mcap::Header header;
  std::uint64_t file_size = 0;
  bool scanned = false;     // true: no usable summary, the whole file was read record by record
  std::string scan_reason;  // why (when scanned)
  std::uint64_t messages = 0;
  mcap::Timestamp start = 0, end = 0;  // log times (ns) of the first and last message
  std::uint64_t chunks = 0;
  std::vector<CompressionStats> compression;  // by compression name
  std::vector<ChannelSummary> channels;       // by id
  std::uint64_t schemas = 0;
  std::vector<mcap::AttachmentIndex> attachments;
  std::vector<std::string> metadata;  // names
  std::uint64_t attachment_count = 0, metadata_count = 0;
};
// Reads the summary (Statistics, chunk indexes, schemas, channels), or scans the file when it has
// none, and checks the data section CRC (so a corrupted file is an Error, not a plausible report).
Result<LogInfo> info(const std::string& path);
// `mcap info`-style text.
std::string format_info(const LogInfo& info);

// doctor --------------------------------------------------------------------------------------
struct DoctorOptions {
  bool strict_message_order = false;  // messages out of log-time order are errors, not warnings
};
struct DoctorFinding {
  bool error = false;  // false: warning
  std::string text;
};
struct DoctorReport {
  std::vector<DoctorFinding> findings;  // in the order found
  std::uint64_t errors = 0, warnings = 0;
  bool ok() const { return errors == 0; }
  std::string first_error() const;
};
// The checks of the official `mcap doctor` (go/cli/mcap/cmd/doctor.go) and a few more: magic,
// header/footer, record framing, chunk decompression and CRCs, message indexes against the
// messages, chunk indexes against the chunks and their message indexes, statistics against the
// data, summary offsets against the summary groups, attachment/metadata indexes, data section and
// summary CRCs, schema/channel references, log-time order. Never fails: an unreadable file is a
// report with an error.
DoctorReport doctor(const std::string& path, const DoctorOptions& options = {});

// recover -------------------------------------------------------------------------------------
struct RecoverOptions {
  mcap::Compression compression = mcap::Compression::Zstd;
  std::uint64_t chunk_size = 1 << 20;
};
struct RecoverReport {
  std::uint64_t input_size = 0;
  bool input_intact = false;     // read to its trailing magic without a problem
  std::uint64_t stopped_at = 0;  // offset where reading stopped (input_size when intact)
  std::string problem;           // what was wrong with the input (empty when intact)
  std::uint64_t messages = 0, schemas = 0, channels = 0, attachments = 0, metadata = 0;
  std::uint64_t chunks = 0;             // complete chunks copied
  std::uint64_t incomplete_chunks = 0;  // chunks cut off by the end of the file (their messages are lost)
  std::uint64_t corrupt_chunks = 0;     // chunks that failed CRC or decompression (skipped)
  std::uint64_t dropped_messages = 0;   // complete messages that could not be kept (unknown channel)
  std::vector<std::string> notes;       // one line per dropped record kind
  std::string summary() const;          // multi-line human-readable report
};
// Streams `in` up to its first unreadable record and writes every complete Schema, Channel,
// Message, Attachment and Metadata (same ids, same profile and library) into a fully indexed
// `out`, written under a temporary name and renamed into place. An Error means nothing was
// written: `in` cannot be read at all (not MCAP, empty, no complete Header), `out` is `in`, or
// `out` cannot be written. A damaged input is not an Error: see RecoverReport::input_intact.
Result<RecoverReport> recover(const std::string& in, const std::string& out,
                              const RecoverOptions& options = {});

// Empty when `path` is a file that can be read and is not empty; otherwise what is wrong
// ("cannot open: ...", "is a directory", "empty file (0 bytes): not an MCAP file").
std::string unreadable(const std::string& path);
// "1.500000000" seconds for a nanosecond timestamp.
std::string seconds(std::uint64_t ns);
// A read error in mcap::describe_read_error's words, with a hint of which tool helps
// ("truncated: ... (rbsim log recover rebuilds ...)").
std::string read_error(const Error& error);

}  // namespace rbsim::mcap_tools
