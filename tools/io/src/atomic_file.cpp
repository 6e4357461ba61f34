#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

#include "rbsim/io.hpp"

namespace rbsim {

namespace {
Error io_error(const std::string& what, const std::string& path) {
  return Error{path + ": " + what + ": " + std::strerror(errno)};
}
}  // namespace

AtomicFile::~AtomicFile() {
  discard();
}

Status AtomicFile::open(const std::string& path) {
  discard();
  path_ = path;
  temp_path_ = path + ".tmp." + std::to_string(::getpid());
  file_ = std::fopen(temp_path_.c_str(), "wb");
  if (file_ == nullptr) return io_error("cannot create output file", path);
  static constexpr std::size_t kBuffer = 1 << 20;
  std::setvbuf(file_, nullptr, _IOFBF, kBuffer);
  bytes_ = 0;
  return Ok{};
}

Status AtomicFile::write(const void* data, std::size_t size) {
  if (file_ == nullptr) return Error{path_ + ": write to a file that is not open"};
  if (size != 0 && std::fwrite(data, 1, size, file_) != size) return io_error("write failed", path_);
  bytes_ += size;
  return Ok{};
}

Status AtomicFile::commit() {
  if (file_ == nullptr) return Error{path_ + ": commit of a file that is not open"};
  const bool flushed = std::fflush(file_) == 0 && ::fsync(::fileno(file_)) == 0;
  const int saved = errno;
  const bool closed = std::fclose(file_) == 0;
  file_ = nullptr;
  if (!flushed || !closed) {
    errno = flushed ? errno : saved;
    Error e = io_error("write failed", path_);
    std::remove(temp_path_.c_str());
    return e;
  }
  if (std::rename(temp_path_.c_str(), path_.c_str()) != 0) {
    Error e = io_error("cannot move output into place", path_);
    std::remove(temp_path_.c_str());
    return e;
  }
  return Ok{};
}

void AtomicFile::discard() {
  if (file_ != nullptr) {
    std::fclose(file_);
    file_ = nullptr;
    std::remove(temp_path_.c_str());
  }
}

}  // namespace rbsim
