// rbsim logs: runs recorded to MCAP in the rosbag2 layout (profile "ros2", "ros2msg" schemas,
// "cdr" messages, "offered_qos_profiles" channel metadata), so Foxglove and `ros2 bag` open them.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "rbsim/io.hpp"
#include "rbsim/mcap.hpp"
#include "rbsim/msgs.hpp"

namespace rbsim::log {

struct RecordOptions {
  mcap::Compression compression = mcap::Compression::Zstd;
  int compression_level = 0;           // 0: the codec's default (check_compression_level)
  std::uint64_t chunk_size = 1 << 20;  // uncompressed bytes per chunk
  std::int64_t every = 1;              // record every k-th step (step 0 always)
  std::string ns = "rbsim";            // ROS namespace of the topics
  std::vector<msgs::TopicId> topics;   // empty: every topic
};

// A Sink that records a run: the scene description once at step 0, then every per-step topic.
// log_time = publish_time = simulated time in ns, so a recording is deterministic.
std::unique_ptr<Sink> make_mcap_sink(std::string path, RecordOptions options = {});

// Adds the schema and channel of `spec` to a writer in the rosbag2 layout; returns the channel id.
// The channel's offered_qos_profiles say `offered` (by default what rbsim's node offers).
mcap::Result<std::uint16_t> add_topic(mcap::Writer& writer, const msgs::TopicSpec& spec, std::string_view ns,
                                      const msgs::OfferedQos& offered);
mcap::Result<std::uint16_t> add_topic(mcap::Writer& writer, const msgs::TopicSpec& spec, std::string_view ns);
// The writer options of every rbsim log (profile "ros2", library "rbsim <version>").
mcap::WriterOptions writer_options(mcap::Compression compression, std::uint64_t chunk_size = 1 << 20,
                                   int compression_level = 0);

// Parses "zstd", "lz4", "none".
bool parse_compression(std::string_view name, mcap::Compression& out);
// Empty when `level` suits the codec: zstd -50..22 (negative: faster, larger), lz4 0..12 (frame
// compression levels; 3 and up are LZ4-HC), none 0 only. Otherwise what is wrong.
std::string check_compression_level(mcap::Compression compression, int level);

}  // namespace rbsim::log

// ---------------------------------------------------------------------------------------------
// Golden-log checks (src/check.cpp, src/check_golden.cpp; test/golden/README.md): two recordings
// compared message by message and field by field, and the verification a golden log passes
// before it is written.

#include <optional>

namespace rbsim::log {

struct CheckOptions {
  double atol = 0.0;  // a float field matches when |actual - expected| <= atol + rtol * |expected|
  double rtol = 0.0;  // (both 0: bit-exact, right for goldens made by the same binary)
  std::vector<std::string> topics;          // compare only these topics (empty: every topic)
  std::vector<std::string> exclude_topics;  // never compare these
  // Log times differ between a live recording (receive time) and `rbsim run --record` (simulated
  // time) of the same run; payloads do not.
  bool compare_log_time = true;
};

// Where two recordings first differ. `field` is the full path ("bodies[3].x"), or for a message-
// or topic-level difference a description in parentheses ("(message missing from the run)").
struct Divergence {
  std::string topic;
  bool has_step = false;  // true: `step` is the message's step field; false: message index
  std::uint64_t step = 0;
  std::string field;
  std::string expected, actual, difference;  // golden value, run value, actual - expected
  bool topic_level = false;                  // the topic itself differs (not one message)
  std::string line() const;                  // "topic /rbsim/body_states, step 200, field ..."
};

// Per topic, per field with array indices collapsed ("bodies[].x"): the largest difference.
struct FieldStats {
  std::string topic, field;
  std::string kind;          // "float", "int", "uint", "bool", "string", "length", "bytes", "time"
  std::uint64_t values = 0;  // values compared
  std::uint64_t over = 0;    // values outside the tolerance (or unequal, for exact kinds)
  double max_abs = 0.0;      // max |actual - expected| (1 for an unequal string/bool/bytes)
  double max_rel = 0.0;      // max |actual - expected| / |expected| (inf when expected is 0)
  bool has_step = false;
  std::uint64_t step_at_max = 0;  // step (or message index) of max_abs
};

struct CheckReport {
  std::optional<Divergence> first;                // none: the recordings match
  std::uint64_t diverging_values = 0;             // values outside the tolerance
  std::uint64_t diverging_messages = 0;           // messages with such a value, plus missing and extra ones
  std::vector<std::string> topic_problems;        // topic-level differences (only in one file, schema)
  std::vector<FieldStats> fields;                 // topics by name, then fields in message order
  std::vector<std::string> topics;                // topics compared
  std::uint64_t messages = 0;                     // message pairs compared
  std::uint64_t run_bytes = 0, golden_bytes = 0;  // uncompressed message data read
  bool passed() const { return !first.has_value(); }
};

// Compares a recording with a golden one. Messages pair up per topic in file order (rbsim writes
// every topic in log-time order); a missing or extra message, a topic in only one file, a
// different schema, log time or any field value outside the tolerance is a divergence. Integers,
// strings, bools and sequence lengths compare exactly. An Error means the inputs could not be
// read (not MCAP, truncated, corrupted, bad CDR): a different outcome from a divergence.
Result<CheckReport> check_logs(const std::string& run_path, const std::string& golden_path,
                               const CheckOptions& options = {});

// Golden logs ---------------------------------------------------------------------------------

// The record-every K a golden of a scene with `steps` steps is recorded with: about 500 recorded
// steps, preferring a K that divides `steps` so the final state is in the log.
std::int64_t golden_record_every(std::int64_t steps);

// The FOSSSim public scene whose file contents equal `scene_path`'s, under
// `<fosssim_dir>/scenes/**`, and its reference output `<fosssim_dir>/reference/<group>/<name>.bin.zst`
// (empty when the reference is not there).
struct FosssimMatch {
  std::string scene;      // empty: no public scene has these contents
  std::string reference;  // empty: no reference output for it
};
FosssimMatch find_fosssim_reference(const std::string& scene_path, const std::string& fosssim_dir);

struct GoldenVerifyOptions {
  std::string fosssim_dir;        // test/data/fosssim; empty: no reference lookup
  double state_tol = 1e-9;        // golden body states vs the reference's free run (absolute)
  double quantity_tol = 1e-8;     // golden M, I, P, L, T, U vs the reference's (absolute)
  double recompute_rtol = 1e-9;   // recorded energy / spring / pose terms vs recomputed ones
  double integration_tol = 1e-9;  // K steps of the verifier's integrator vs the next recorded state
};

struct GoldenVerification {
  bool passed = false;
  // The independent results it was checked against, e.g. "fosssim-reference,
  // independent-integration" or "symplectic-energy, independent-integration".
  std::string rule;
  std::vector<std::string> lines;  // "PASS ..." / "FAIL ..." per check, "info ..." notes
  std::int64_t record_every = 0, last_step = 0, steps = 0;
  double energy_error = 0.0, energy_bound = 0.0;  // symplectic-energy rule
};

// Verifies a golden log of a scene independently of the simulator (its own code throughout; of
// sim_core only the scene loader, and grade() for the reference rule): the recorded scene description against
// the scene file (M, I and hulls recomputed from the vertices), the recording's steps and stamps, every
// recorded energy, spring and pose term recomputed from the recorded body states, and the dynamics:
//  - independent-integration (every scene): from each recorded state, K steps of the verifier's
//    own integrator (forces summed as the spec states them, the wind over its sample points) land
//    on the next recorded state within integration_tol;
//  - fosssim-reference, when the scene has a FOSSSim reference output (matched by file contents):
//    rbsim's grade() passes and the golden's body states and quantities at every recorded step
//    equal the reference's within state_tol / quantity_tol;
//  - symplectic-energy, for symplectic Euler with gravity and springs only and no reference: the
//    total energy E = T + U recomputed from the recorded states stays within
//    dt * (max_n |Pi_n| + |Pi_0|) (+ rounding) of E_0, Pi being the power of the conservative
//    forces: twice the first-order backward-error estimate (dt/2) |Pi_n - Pi_0|.
Result<GoldenVerification> verify_golden(const std::string& scene_path, const std::string& golden_path,
                                         const GoldenVerifyOptions& options = {});

// The record-every K of an existing golden log (step of its second body-state message), 1 when
// it holds a single step.
Result<std::int64_t> read_record_every(const std::string& golden_path);

}  // namespace rbsim::log

// ---------------------------------------------------------------------------------------------
// Log tools (src/info.cpp, doctor.cpp, recover.cpp, export.cpp): `rbsim log info | doctor |
// recover | export`. No input crashes or hangs them: every loop is bounded by the bytes read.

#include <map>

namespace rbsim::log {

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

// export --------------------------------------------------------------------------------------
struct ExportOptions {
  std::string csv;         // per-body CSV (rbsim run --csv), empty: none
  std::string energy_csv;  // scene totals CSV (rbsim run --energy-csv), empty: none
  std::string ns;          // ROS namespace of the topics; empty: the only one in the file
};
struct ExportReport {
  std::uint64_t steps = 0;  // steps written
  std::uint64_t first_step = 0, last_step = 0;
  std::vector<std::string> warnings;
};
// Re-creates `rbsim run --csv / --energy-csv` output from a recording, byte for byte, for the
// recorded steps. Topics are found by type (rbsim_msgs/msg/SceneDescription, BodyStates,
// EnergyTerms); their schemas must equal this build's.
Result<ExportReport> export_csv(const std::string& path, const ExportOptions& options);

}  // namespace rbsim::log
