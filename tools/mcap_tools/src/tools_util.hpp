// Small pieces shared by the log tools (info, doctor, recover, export).
#pragma once

#include <memory>
#include <string>

#include "rbsim/mcap.hpp"
#include "rbsim/mcap_records.hpp"
#include "rbsim/status.hpp"

namespace rbsim::mcap_tools::detail {

// `path` opened for reading, its errors worded as the tools print them after the path
// ("cannot open: <reason>", "is a directory").
Result<std::unique_ptr<mcap::ByteSource>> open_input(const std::string& path);

}  // namespace rbsim::mcap_tools::detail
