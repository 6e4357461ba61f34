// libFuzzer target: the input handling of `rbsim check` and the other log tools. The input is
// written to a file (the tools take paths) and given to check (against itself and against a
// golden log), info, doctor, recover and the recording reader (every step of every topic). Each
// must end with a report or an error, never crash.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "rbsim/check.hpp"
#include "rbsim/mcap_tools.hpp"
#include "rbsim/recording.hpp"

namespace {
std::string temp_path(const char* what) {
  const char* dir = std::getenv("TMPDIR");
  return std::string(dir != nullptr && *dir != '\0' ? dir : "/tmp") + "/rbsim-fuzz-log-" +
         std::to_string(::getpid()) + "-" + what + ".mcap";
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string in = temp_path("in"), out = temp_path("out");
  static const char* golden = std::getenv("RBSIM_FUZZ_GOLDEN");
  std::FILE* f = std::fopen(in.c_str(), "wb");
  if (f == nullptr) __builtin_trap();
  if (size > 0 && std::fwrite(data, 1, size, f) != size) __builtin_trap();
  std::fclose(f);

  rbsim::check::CheckOptions options;
  (void)rbsim::check::check_logs(in, in, options);
  options.compare_log_time = false;
  options.rtol = 1e-9;
  if (golden != nullptr && *golden != '\0') {
    (void)rbsim::check::check_logs(in, golden, options);
    (void)rbsim::check::check_logs(golden, in, options);
  }
  (void)rbsim::mcap_tools::info(in);
  (void)rbsim::mcap_tools::doctor(in);
  (void)rbsim::mcap_tools::recover(in, out);
  rbsim::recordings::RecordingOptions ro;
  ro.require_scene = false;
  if (auto recording = rbsim::recordings::Recording::open(in, ro); recording.ok()) {
    (void)recording.value()->read_steps(
        [](const rbsim::recordings::RecordedStep&) -> rbsim::Status { return rbsim::Ok{}; });
  }
  std::remove(out.c_str());
  return 0;
}
