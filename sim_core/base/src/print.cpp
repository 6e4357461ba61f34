// stderr and the print hook, one path (rbsim/print.hpp).
#include "rbsim/print.hpp"

#include <atomic>
#include <cstdarg>
#include <cstdio>
#include <string>

namespace rbsim::print {

namespace {
std::atomic<Hook> g_hook{nullptr};
}  // namespace

Hook set_hook(Hook hook) {
  return g_hook.exchange(hook);
}

void log(Level level, std::string_view line, std::source_location where) {
  std::fprintf(stderr, "%.*s\n", static_cast<int>(line.size()), line.data());
  if (const Hook hook = g_hook.load()) hook(level, line, where);
}

void logf(Level level, std::source_location where, const char* format, ...) {
  std::va_list args;
  va_start(args, format);
  std::va_list copy;
  va_copy(copy, args);
  const int n = std::vsnprintf(nullptr, 0, format, copy);
  va_end(copy);
  std::string text(n > 0 ? static_cast<std::size_t>(n) : 0, '\0');
  if (n > 0) std::vsnprintf(text.data(), text.size() + 1, format, args);
  va_end(args);
  // Lines end where log() ends them.
  while (!text.empty() && text.back() == '\n') text.pop_back();
  log(level, text, where);
}

}  // namespace rbsim::print
