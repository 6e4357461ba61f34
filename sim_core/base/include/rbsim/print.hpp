// The one printing path of every command: each line goes to stderr and then, while one is set, to
// the process's print hook. rbsim's ROS 2 commands (node, record, replay, bridge) set the hook while
// their node's /rosout publisher lives (node/dds's Rosout), so the same lines also go to /rosout; a
// command without a node (run, check, render, the log tools) prints through the same functions and
// links no middleware.
#pragma once

#include <cstdint>
#include <source_location>
#include <string_view>

namespace rbsim::print {

// The levels of rcl_interfaces/msg/Log (msgs::LogLevel is this type).
enum class Level : std::uint8_t { Debug = 10, Info = 20, Warn = 30, Error = 40, Fatal = 50 };

// Writes `line` and a newline to stderr, then hands it to the hook, if any.
void log(Level level, std::string_view line, std::source_location where = std::source_location::current());
// printf-style log() for the call sites that format (RBSIM_LOG); trailing newlines are dropped.
[[gnu::format(printf, 3, 4)]] void logf(Level level, std::source_location where, const char* format, ...);

// Receives every line after stderr did, on the thread that logged it; must not log itself.
using Hook = void (*)(Level level, std::string_view line, const std::source_location& where);
// Sets the hook (null: none); returns the one it replaces.
Hook set_hook(Hook hook);

}  // namespace rbsim::print

#define RBSIM_LOG(level, ...) \
  ::rbsim::print::logf(::rbsim::print::Level::level, std::source_location::current(), __VA_ARGS__)
