// Small pieces shared by the rbsim subcommands: Ctrl-C handling and a terminal progress bar.
#pragma once

#include <chrono>
#include <cstdint>
#include <source_location>
#include <string>

#include "rbsim/core.hpp"
#include "rbsim/mcap.hpp"

namespace rbsim::cli {

// Installs SIGINT/SIGTERM handlers that only raise a flag; long loops poll stop_requested() and
// shut down cleanly (outputs finished, summary printed).
void install_stop_handlers();
bool stop_requested();
int stop_signal();  // the signal that asked to stop, or 0
// Asks to stop as a signal would, from inside (simulation_interfaces' STATE_QUITTING).
void request_stop();

// A one-line progress bar on stderr, shown only on a terminal and only once a run has taken
// longer than `delay`. update() is cheap enough to call every step: it looks at the clock only
// every few hundred calls.
class Progress {
 public:
  enum class Mode { Auto, Always, Never };
  Progress(std::int64_t total, Mode mode, std::chrono::milliseconds delay = std::chrono::milliseconds(1000));
  ~Progress();
  void update(std::int64_t done) {
    if (enabled_ && ++calls_ >= stride_) tick(done);
  }
  void finish();

 private:
  void tick(std::int64_t done);
  std::int64_t total_;
  bool enabled_ = false, shown_ = false;
  std::uint32_t calls_ = 0, stride_ = 256;
  std::chrono::steady_clock::time_point start_, last_draw_;
  std::chrono::milliseconds delay_;
};

std::string format_seconds(double seconds);

// A file or folder rbsim ships: installed beside the binary (<prefix>/share/rbsim/<installed>, cmake
// --install and the Debian package), else in the source tree the binary was built from (<source>).
std::string bundled_path(const std::string& installed, const std::string& source);

// --compression NAME with --compression-level LEVEL (0: the codec's default) as one codec choice;
// the error names the option that is wrong.
Result<mcap::Compression> compression_option(const std::string& name, int level = 0);

// Prints "rbsim COMMAND: error: MESSAGE" on stderr (and, in a DDS command, on /rosout: the one
// printing path, rbsim/print.hpp, whose hook is the node's Rosout); returns the exit status to end with.
int fail(const char* command, const std::string& message, int exit_status = 1,
         std::source_location where = std::source_location::current());

// "1 body", "2 bodies": a count with its noun in the right number (rbsim::plural decides).
std::string count_of(std::int64_t n, const char* one, const char* many);

}  // namespace rbsim::cli
