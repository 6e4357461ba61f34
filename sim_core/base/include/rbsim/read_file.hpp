// Reading a whole file into memory: the one reader of whole input files (scenes, reference
// outputs, goldens compared byte for byte). Streams (recordings) are read through mcap::ByteSource.
#pragma once

#include <string>
#include <string_view>

#include "rbsim/bytes.hpp"
#include "rbsim/status.hpp"

namespace rbsim {

// The file's bytes. A file that cannot be opened is "<path>: cannot open <what>: <reason>" (or
// "<path>: cannot open: <reason>" without `what`), a failed read "<path>: read error"; both
// ErrorCode::IoError.
[[nodiscard]] Result<Bytes> read_whole_file(const std::string& path, std::string_view what = {});
// The same bytes as text (XML, YAML).
[[nodiscard]] Result<std::string> read_text_file(const std::string& path, std::string_view what = {});

}  // namespace rbsim
