#include "rbsim/atomic_file.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>

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

// How many bytes reached the file (a failed write's report): its size, else what was handed to it.
std::uint64_t on_disk(std::FILE* file, std::uint64_t handed) {
  struct stat st {};
  if (file != nullptr && ::fstat(::fileno(file), &st) == 0) return static_cast<std::uint64_t>(st.st_size);
  return handed;
}

// An unnamed file in `path`'s folder (O_TMPFILE), linked into place by commit(): nothing of it is
// left when the process dies, SIGKILL included. -1 where the file system cannot (errno says why).
int open_unnamed(const std::string& path, unsigned mode = 0666) {
  std::string dir = path.substr(0, path.find_last_of('/') + 1);
  if (dir.empty()) dir = ".";
  return ::open(dir.c_str(), O_TMPFILE | O_WRONLY | O_CLOEXEC, mode);  // less the umask, as fopen's
}

Status AtomicFile::open(const std::string& path, unsigned mode) {
  open_external(path);
  external_ = false;
  int fd = open_unnamed(path, mode);
  if (fd >= 0) {
    temp_path_.clear();  // unnamed until commit()
  } else {
    // A file system without O_TMPFILE: a named temporary, created here with `mode` (never an
    // existing file or a link: a private file is private from its first byte).
    std::remove(temp_path_.c_str());
    fd = ::open(temp_path_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, mode);
  }
  if (fd >= 0) {
    file_ = ::fdopen(fd, "wb");
    if (file_ == nullptr) ::close(fd);
  }
  if (file_ == nullptr) {
    pending_ = false;
    return io_error("cannot create output file", path, errno);
  }
  static constexpr std::size_t kBuffer = 1 << 20;
  std::setvbuf(file_, nullptr, _IOFBF, kBuffer);
  return Ok{};
}

// Removes `<path>.tmp.<pid>` files whose process is gone: a killed writer's leftovers.
static void remove_leftovers(const std::string& path) {
  namespace fs = std::filesystem;
  const fs::path p(path);
  const fs::path dir = p.has_parent_path() ? p.parent_path() : fs::path(".");
  const std::string prefix = p.filename().string() + ".tmp.";
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.size() <= prefix.size() || name.compare(0, prefix.size(), prefix) != 0) continue;
    const std::string digits = name.substr(prefix.size());
    if (digits.size() > 9 || digits.find_first_not_of("0123456789") != std::string::npos) continue;
    const auto pid = static_cast<pid_t>(std::stol(digits));
    if (pid == ::getpid() || ::kill(pid, 0) == 0 || errno != ESRCH) continue;
    fs::remove(entry.path(), ec);
  }
}

void AtomicFile::open_external(const std::string& path, Leftovers leftovers) {
  discard();
  path_ = path;
  temp_path_ = path + ".tmp." + std::to_string(::getpid());
  pending_ = true;
  bytes_ = 0;
  external_ = true;
  if (leftovers == Leftovers::Keep) return;
  remove_leftovers(path);
  // Nothing of a killed writer may stay: the writer gets an unnamed file, which this process
  // holds open (and links at commit), by its /proc path.
  const int fd = open_unnamed(path);
  if (fd < 0) return;
  file_ = ::fdopen(fd, "wb");
  if (file_ == nullptr) {
    ::close(fd);
    return;
  }
  temp_path_.clear();
}

std::string AtomicFile::writer_path() const {
  return file_ != nullptr ? open_file_path(::fileno(file_)) : temp_path_;
}

std::string open_file_path(int fd) {
  return "/proc/" + std::to_string(::getpid()) + "/fd/" + std::to_string(fd);
}

Status AtomicFile::write(const void* data, std::size_t size) {
  if (file_ == nullptr || external_) return Error{path_ + ": write to a file that is not open"};
  if (size != 0 && std::fwrite(data, 1, size, file_) != size) {
    const int error = errno;
    return io_error("write failed after " + std::to_string(on_disk(file_, bytes_)) + " bytes", path_, error);
  }
  bytes_ += size;
  return Ok{};
}

Status AtomicFile::commit(Durability durability) {
  if (!pending_) return Error{path_ + ": commit of a file that is not open"};
  const bool sync = durability == Durability::Fsync;
  bool written = true;
  int error = 0;
  std::uint64_t reached = bytes_;
  const bool external = external_;
  if (file_ != nullptr) {
    const bool flushed = std::fflush(file_) == 0 && (!sync || ::fsync(::fileno(file_)) == 0);
    error = errno;  // the flush's, if it failed; else the link's or the close's
    bool linked = true;
    if (flushed && temp_path_.empty()) {
      // The unnamed file gets a name beside its path (linkat cannot replace one), then the
      // rename below moves it over the path.
      temp_path_ = path_ + ".tmp." + std::to_string(::getpid());
      std::remove(temp_path_.c_str());
      const std::string self = "/proc/self/fd/" + std::to_string(::fileno(file_));
      linked = ::linkat(AT_FDCWD, self.c_str(), AT_FDCWD, temp_path_.c_str(), AT_SYMLINK_FOLLOW) == 0;
      if (!linked) {
        error = errno;
        temp_path_.clear();
      }
    }
    if (!flushed || !linked) reached = on_disk(file_, bytes_);
    const bool closed = std::fclose(file_) == 0;
    if (flushed && linked) error = errno;
    written = flushed && linked && closed;
    file_ = nullptr;
  } else if (sync) {
    written = sync_path(temp_path_);
    error = errno;
  }
  if (!written) {
    // An external writer's bytes are its own: only ours are counted.
    Error e = io_error(external ? "write failed" : "write failed after " + std::to_string(reached) + " bytes",
                       path_, error);
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
    if (!temp_path_.empty()) std::remove(temp_path_.c_str());  // an unnamed one went with its file
    pending_ = false;
  }
}

}  // namespace rbsim
