#include "rbsim/atomic_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

namespace rbsim {

namespace {
Error io_error(const std::string& what, const std::string& path, int error) {
  return Error{path + ": " + what + ": " + std::strerror(error)};
}

// fsync by name, for a file another writer closed: the data is on disk before the rename makes
// it the output.
bool sync_path(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY);
  if (fd < 0) return false;
  const bool synced = ::fsync(fd) == 0;
  const int saved = errno;
  ::close(fd);
  errno = saved;
  return synced;
}
}  // namespace

AtomicFile::~AtomicFile() {
  discard();
}

Status AtomicFile::open(const std::string& path) {
  open_external(path);
  file_ = std::fopen(temp_path_.c_str(), "wb");
  if (file_ == nullptr) {
    pending_ = false;
    return io_error("cannot create output file", path, errno);
  }
  static constexpr std::size_t kBuffer = 1 << 20;
  std::setvbuf(file_, nullptr, _IOFBF, kBuffer);
  return Ok{};
}

void AtomicFile::open_external(const std::string& path) {
  discard();
  path_ = path;
  temp_path_ = path + ".tmp." + std::to_string(::getpid());
  pending_ = true;
  bytes_ = 0;
}

Status AtomicFile::write(const void* data, std::size_t size) {
  if (file_ == nullptr) return Error{path_ + ": write to a file that is not open"};
  if (size != 0 && std::fwrite(data, 1, size, file_) != size) return io_error("write failed", path_, errno);
  bytes_ += size;
  return Ok{};
}

Status AtomicFile::commit(Durability durability) {
  if (!pending_) return Error{path_ + ": commit of a file that is not open"};
  const bool sync = durability == Durability::Fsync;
  bool written = true;
  int error = 0;
  if (file_ != nullptr) {
    const bool flushed = std::fflush(file_) == 0 && (!sync || ::fsync(::fileno(file_)) == 0);
    error = errno;  // the flush's, if it failed; else the close's
    const bool closed = std::fclose(file_) == 0;
    if (flushed) error = errno;
    written = flushed && closed;
    file_ = nullptr;
  } else if (sync) {
    written = sync_path(temp_path_);
    error = errno;
  }
  if (!written) {
    Error e = io_error("write failed", path_, error);
    discard();
    return e;
  }
  if (std::rename(temp_path_.c_str(), path_.c_str()) != 0) {
    Error e = io_error("cannot move output into place", path_, errno);
    discard();
    return e;
  }
  pending_ = false;
  return Ok{};
}

void AtomicFile::discard() {
  if (file_ != nullptr) {
    std::fclose(file_);
    file_ = nullptr;
  }
  if (pending_) {
    std::remove(temp_path_.c_str());
    pending_ = false;
  }
}

}  // namespace rbsim
