// Records in the JSON shape of the MCAP conformance suite: {"type", "fields": [[name, value]...]}
// with snake_case field names sorted, scalars as decimal strings, bytes as arrays of decimal
// strings and maps as objects.
#pragma once

#include <nlohmann/json.hpp>

#include "rbsim/mcap.hpp"
#include "rbsim/test_bytes.hpp"

namespace rbsim::mcap::test {

nlohmann::json record_to_json(const Record& record);

// What foxglove's indexed-reader runner expects, derived from a streamed record list: unique
// schemas and channels sorted by id, messages stably sorted by log time, and the statistics.
nlohmann::json indexed_view_of(const nlohmann::json& streamed_records);

Bytes read_file(const std::string& path);

}  // namespace rbsim::mcap::test
