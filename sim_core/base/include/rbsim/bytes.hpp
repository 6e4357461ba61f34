// The one byte buffer of rbsim: MCAP records, CDR messages, files read whole. std::byte, not
// uint8_t or char: these are raw data, never arithmetic or text, and the type says so (reading a
// number out of them is an explicit std::to_integer or memcpy, never an implicit promotion).
#pragma once

#include <cstddef>
#include <span>
#include <vector>

namespace rbsim {

using Bytes = std::vector<std::byte>;
using ByteView = std::span<const std::byte>;

}  // namespace rbsim
