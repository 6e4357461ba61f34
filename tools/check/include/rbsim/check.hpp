// rbsim check: two recordings compared message by message and field by field (src/check.cpp).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "rbsim/core.hpp"

namespace rbsim::check {

struct CheckOptions {
  double atol = 0.0;  // a float field matches when |actual - expected| <= atol + rtol * |expected|
  double rtol = 0.0;  // (both 0: bit-exact, right for goldens made by the same binary)
  std::vector<std::string> topics;          // compare only these topics (empty: every topic)
  std::vector<std::string> exclude_topics;  // never compare these
  // Log times differ between a live recording (receive time) and `rbsim run --record` (simulated
  // time) of the same run; payloads do not.
  bool compare_log_time = true;
  // Metadata (the scene's name, description, viewport and background, the MCAP header's profile
  // and library) is reported apart from physics; true makes a metadata difference a divergence.
  bool strict_metadata = false;
};

// Where two recordings first differ. `field` is the full path ("bodies[3].x"), or for a message-
// or topic-level difference a description in parentheses ("(message missing from the run)").
struct FirstDifference {
  std::string topic;
  bool has_step = false;  // true: `step` is the simulated step; false: the message's index on its topic
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

// A metadata value that differs (not physics: reported, a divergence only with strict_metadata).
struct MetadataDifference {
  std::string where;             // "/rbsim/scene, field name" or "MCAP header, library"
  std::string expected, actual;  // golden value, run value
  std::string line() const;      // "/rbsim/scene, field name: expected "chain", actual "mychain""
};

struct CheckReport {
  std::optional<FirstDifference> first;     // none: the recordings match
  std::uint64_t diverging_values = 0;       // values outside the tolerance
  std::uint64_t diverging_messages = 0;     // messages with such a value, plus missing and extra ones
  std::uint64_t one_file_messages = 0;      // of those: per-step messages whose step one file lacks
  std::vector<std::string> topic_problems;  // topic-level differences (only in one file, schema)
  // Per topic, the simulated steps only in the golden ("run lacks") or only in the run ("run has
  // extra"), with their ranges and a likely cause: "/rbsim/body_states: run lacks steps 0..999
  // (1,000 messages: recorder joined late?)", "... golden recorded every 10th step, run every 5th".
  std::vector<std::string> step_problems;
  // Non-empty when the two files record different scenes (bodies, hull vertices, which bodies the
  // springs join, force fields, integrator): why, in one line. Nothing else is then compared.
  std::string scene_mismatch;
  std::vector<MetadataDifference> metadata;       // metadata differences (first per field)
  std::vector<FieldStats> fields;                 // topics by name, then fields in message order
  std::vector<std::string> topics;                // topics compared
  std::uint64_t messages = 0;                     // message pairs compared
  std::uint64_t run_bytes = 0, golden_bytes = 0;  // uncompressed message data read
  bool passed() const { return !first.has_value(); }
};

// Compares a recording with a golden one. Per-step messages (rbsim's body states, spring states,
// energy terms, /tf, springs, poses and clock) pair up per topic by simulated step, msgs::message_step
// (the step a message carries, else round(stamp / dt) with each file's dt from its scene
// description); other messages (the latched scene description and markers,
// topics of other types, a file without a scene description) pair up per topic in file order.
// A step (or message) in only one file, a topic in only one file, a different schema, log time or
// any physics field value outside the tolerance is a divergence; metadata is reported apart. Integers,
// strings, bools and sequence lengths compare exactly. An Error means the inputs could not be
// read (not MCAP, truncated, corrupted, bad CDR): a different outcome from a divergence.
Result<CheckReport> check_logs(const std::string& run_path, const std::string& golden_path,
                               const CheckOptions& options = {});

struct ReportFormat {
  bool all_fields = false;             // list identical fields in the table too
  std::optional<double> wall_seconds;  // how long the comparison took, printed with its MB/s
};
// The report `rbsim check` prints for `report`: the verdict, the first divergence (topic, step,
// field, expected, actual, difference), topic and step problems, metadata, the per-field
// max-error table and the totals. rbsim::testing::CheckLogs shows the same text.
std::string format_report(const std::string& run_path, const std::string& golden_path,
                          const CheckOptions& options, const CheckReport& report,
                          const ReportFormat& format = {});

}  // namespace rbsim::check
