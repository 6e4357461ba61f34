// Rebuilds an MCAP conformance input from its expected-output JSON, byte for byte, following
// foxglove's generator (tests/conformance/scripts/generate-inputs.ts with @mcap/core's
// McapRecordBuilder and ChunkBuilder). The MCAP repository keeps the suite's .mcap files as Git LFS pointers
// instead of the binaries; rebuilding and checking the pointer's SHA-256 recovers the official files.
#pragma once

#include <nlohmann/json.hpp>

#include "rbsim/mcap.hpp"

namespace rbsim::mcap::test {

Bytes generate_conformance_file(const nlohmann::json& expected);

// SHA-256 (FIPS 180-4) as lowercase hex, to compare with the LFS pointers' oids.
std::string sha256_hex(ByteView data);

}  // namespace rbsim::mcap::test
