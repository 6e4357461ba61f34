// `rbsim log cat`: every message of a recording as one line of JSON, decoded by its ros2msg schema,
// the way `mcap cat --json` prints it; or one topic as CSV.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "rbsim/core.hpp"

namespace rbsim::recordings {

enum class CatFormat { Json, Csv };

struct CatOptions {
  // Topics to print, each as recorded ("/rbsim/body_states") or by its last name part(s)
  // ("body_states"); a name that matches no channel is an error. Empty: every topic.
  std::vector<std::string> topics;
  std::optional<double> start, end;  // log time in seconds: start inclusive, end exclusive
  // Csv: one topic (the one `topics` names, or the file's only one), a header line of columns
  // log_time,publish_time,sequence and the first message's flattened fields as
  // MessageDecoder::path names them ("bodies[2].x", "bodies.length"), then one line per message
  // (floats shortest round-trip, strings quoted when they must be). A message of another shape
  // (other sequence lengths) is an error.
  CatFormat format = CatFormat::Json;
};

// Json: calls `on_line` with one JSON object (no newline) per message, in log-time order (equal times in
// file order):
//   {"topic":"/rbsim/body_states","sequence":3,"log_time":30000000,"publish_time":30000000,
//    "data":{...}}
// log_time and publish_time are integer nanoseconds as recorded; data is the message decoded from
// its channel's ros2msg schema (msgs::MessageDecoder::to_json: nested objects and arrays, non-finite
// floats as null), or null when the channel has no ros2msg schema with CDR encoding. Fails on an
// unreadable or corrupt file, a message that its schema cannot decode, or an unknown topic; for
// Csv also on several topics, a topic without a ros2msg/CDR schema or a message of another shape.
[[nodiscard]] Status cat(const std::string& path, const CatOptions& options,
                         const std::function<void(std::string_view line)>& on_line);

}  // namespace rbsim::recordings
