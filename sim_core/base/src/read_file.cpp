#include "rbsim/read_file.hpp"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

namespace rbsim {

namespace {

// Reads into any contiguous container of bytes or chars; one place for the open and error rules.
template <class Buffer>
Result<Buffer> read_into(const std::string& path, std::string_view what) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) return Error{path + ": is a directory", ErrorCode::IoError};
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    std::string message = path + ": cannot open";
    if (!what.empty()) message += " " + std::string(what);
    return Error{message + ": " + std::strerror(errno), ErrorCode::IoError};
  }
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  in.seekg(0, std::ios::beg);
  Buffer out;
  if (size > 0) {  // a regular file: one read of its size
    out.resize(static_cast<std::size_t>(size));
    in.read(reinterpret_cast<char*>(out.data()), static_cast<std::streamsize>(size));
    out.resize(static_cast<std::size_t>(in.gcount()));
  } else {  // a pipe or an empty file: read until the end
    in.clear();
    const std::string rest{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    out.resize(rest.size());
    if (!rest.empty()) std::memcpy(out.data(), rest.data(), rest.size());
  }
  if (in.bad()) return Error{path + ": read error", ErrorCode::IoError};
  return out;
}

}  // namespace

Result<Bytes> read_whole_file(const std::string& path, std::string_view what) {
  return read_into<Bytes>(path, what);
}

Result<std::string> read_text_file(const std::string& path, std::string_view what) {
  return read_into<std::string>(path, what);
}

}  // namespace rbsim
