// Output paths checked before any work starts, so a run never ends by throwing its result away
// and never writes over something the user did not ask it to replace (as `ros2 bag record`
// refuses an existing output and ffmpeg asks for -y).
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "rbsim/core.hpp"

namespace rbsim {

struct OutputPath {
  std::string path;     // empty: the output is not wanted (skipped)
  std::string option;   // how the user named it, for messages ("--csv")
  bool folder = false;  // a folder of files (frames): may exist; must not be a file
};

// Ok when every wanted output can be written: its folder exists and is writable, it is not a
// folder (or, for a folder output, not a file), no two outputs are the same file, none is one of
// `inputs` (never, even with `overwrite`), and a file output does not exist yet unless
// `overwrite`. The Error names the option, the path and the rule (an existing file: how the caller
// names `overwrite`, "--overwrite" on the command line).
[[nodiscard]] Status check_outputs(const std::vector<OutputPath>& outputs,
                                   const std::vector<std::string>& inputs, bool overwrite,
                                   std::string_view overwrite_option = "--overwrite");

// Whether two paths name the same file (existing or not: compared by canonical path).
bool same_file(const std::string& a, const std::string& b);

}  // namespace rbsim
