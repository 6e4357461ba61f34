#include "tools_util.hpp"

#include "rbsim/mcap_tools.hpp"

#include <sys/stat.h>

#include <cerrno>
#include <cstring>

namespace rbsim::mcap_tools {
namespace detail {

std::string FileBytes::open(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return std::string("cannot open: ") + std::strerror(errno);
  if (S_ISDIR(st.st_mode)) return "is a directory";
  file_.reset(std::fopen(path.c_str(), "rb"));
  if (!file_) return std::string("cannot open: ") + std::strerror(errno);
  if (fseeko(file_.get(), 0, SEEK_END) != 0) return std::string("cannot seek: ") + std::strerror(errno);
  const off_t end = ftello(file_.get());
  if (end < 0) return std::string("cannot seek: ") + std::strerror(errno);
  size_ = static_cast<std::uint64_t>(end);
  return {};
}

bool FileBytes::read(std::uint64_t offset, std::uint64_t length, mcap::Bytes& out) {
  if (!file_ || offset > size_ || length > size_ - offset) return false;
  out.resize(static_cast<std::size_t>(length));
  if (fseeko(file_.get(), static_cast<off_t>(offset), SEEK_SET) != 0) return false;
  return std::fread(out.data(), 1, out.size(), file_.get()) == out.size();
}

std::string opcode_name(std::uint8_t opcode) {
  static constexpr const char* kNames[] = {"Header",        "Footer",          "Schema",       "Channel",
                                           "Message",       "Chunk",           "MessageIndex", "ChunkIndex",
                                           "Attachment",    "AttachmentIndex", "Statistics",   "Metadata",
                                           "MetadataIndex", "SummaryOffset",   "DataEnd"};
  if (opcode >= 1 && opcode <= 0x0F) return kNames[opcode - 1];
  char buf[24];
  std::snprintf(buf, sizeof buf, "opcode 0x%02x", opcode);
  return buf;
}

}  // namespace detail

std::string seconds(std::uint64_t ns) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%llu.%09llu", static_cast<unsigned long long>(ns / 1'000'000'000),
                static_cast<unsigned long long>(ns % 1'000'000'000));
  return buf;
}

std::string unreadable(const std::string& path) {
  detail::FileBytes f;
  if (std::string e = f.open(path); !e.empty()) return e;
  if (f.size() == 0) return "empty file (0 bytes): not an MCAP file";
  return {};
}

std::string read_error(const mcap::Status& status) {
  switch (status.code) {
    case mcap::StatusCode::Truncated:
      return "truncated: " + status.message +
             " (rbsim log recover rebuilds a valid file from its complete chunks)";
    case mcap::StatusCode::CrcMismatch:
    case mcap::StatusCode::DecompressionFailed:
    case mcap::StatusCode::Malformed:
      return "corrupted: " + status.message + " (rbsim log doctor lists the problems)";
    default:
      return status.message;
  }
}

}  // namespace rbsim::mcap_tools
