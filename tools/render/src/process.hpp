#pragma once
#include <string>
#include <vector>

#include "rbsim/core.hpp"

namespace rbsim::render::detail {
// Runs args[0] (looked up on PATH, no shell); its exit status, or an error naming the program
// when it cannot be started.
Result<int> run_process(const std::vector<std::string>& args);
}  // namespace rbsim::render::detail
