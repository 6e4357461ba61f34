#include "tools_util.hpp"

#include "rbsim/mcap_tools.hpp"

#include <sys/stat.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

namespace rbsim::mcap_tools {
namespace detail {

Result<std::unique_ptr<mcap::ByteSource>> open_input(const std::string& path) {
  // A directory opens (and reads as an error) on Linux: say what it is instead.
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return Error{std::string("cannot open: ") + std::strerror(errno)};
  if (S_ISDIR(st.st_mode)) return Error{"is a directory"};
  auto source = mcap::open_file_source(path);
  if (!source.ok()) {
    // The library names the path ("cannot open 'x': ..."); the tools' callers already did.
    std::string message = source.error().message;
    const std::string quoted = " '" + path + "'";
    if (const std::size_t at = message.find(quoted); at != std::string::npos)
      message.erase(at, quoted.size());
    return Error{message};
  }
  return std::move(source).value();
}

}  // namespace detail

std::string seconds(std::uint64_t ns) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%llu.%09llu", static_cast<unsigned long long>(ns / 1'000'000'000),
                static_cast<unsigned long long>(ns % 1'000'000'000));
  return buf;
}

std::string unreadable(const std::string& path) {
  auto source = detail::open_input(path);
  if (!source) return source.error().message;
  if (source.value()->size() == 0) return "empty file (0 bytes): not an MCAP file";
  return {};
}

std::string read_error(const Error& error) {
  const std::string words = mcap::describe_read_error(error);
  switch (error.code) {
    case ErrorCode::Truncated:
      return words + " (rbsim log recover rebuilds a valid file from its complete chunks)";
    case ErrorCode::CrcMismatch:
    case ErrorCode::DecompressionFailed:
    case ErrorCode::Malformed:
      return words + " (rbsim log doctor lists the problems)";
    default:
      return words;
  }
}

}  // namespace rbsim::mcap_tools
