#include "byte_sink.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <sys/uio.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

namespace rbsim::mcap {
namespace detail {
namespace {

Error io_error(const std::string& what, const std::string& path) {
  return Error{what + " '" + path + "': " + std::strerror(errno), ErrorCode::IoError};
}

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};
using FilePtr = std::unique_ptr<std::FILE, FileCloser>;

class FileSource final : public ByteSource {
 public:
  FileSource(FilePtr file, std::uint64_t size) : file_(std::move(file)), size_(size) {}
  std::uint64_t size() const override { return size_; }
  Status read(std::uint64_t offset, std::uint64_t length, ByteView& out) override {
    if (offset > size_ || length > size_ - offset) return out_of_range(offset, length, size_);
    // The buffer only grows: resizing it down for a record prefix and up again for the next
    // record would zero-fill it each time.
    const std::size_t n = static_cast<std::size_t>(length);
    if (buffer_.size() < n) buffer_.resize(n);
    // Sequential reads (the common case) skip the seek so stdio's read-ahead keeps working.
    if (offset != position_ && fseeko(file_.get(), static_cast<off_t>(offset), SEEK_SET) != 0) {
      position_ = UINT64_MAX;
      return Error{std::string("seek failed: ") + std::strerror(errno), ErrorCode::IoError};
    }
    const std::size_t got = std::fread(buffer_.data(), 1, n, file_.get());
    position_ = offset + got;
    if (got != n) {
      position_ = UINT64_MAX;
      return Error{"short read at offset " + std::to_string(offset), ErrorCode::IoError};
    }
    out = ByteView(buffer_).first(n);
    return Ok{};
  }

 private:
  FilePtr file_;
  std::uint64_t size_ = 0;
  std::uint64_t position_ = 0;
  Bytes buffer_;
};

class BufferSource final : public ByteSource {
 public:
  explicit BufferSource(Bytes data) : data_(std::move(data)) {}
  std::uint64_t size() const override { return data_.size(); }
  Status read(std::uint64_t offset, std::uint64_t length, ByteView& out) override {
    if (offset > data_.size() || length > data_.size() - offset) return out_of_range(offset, length, size());
    out = ByteView(data_).subspan(static_cast<std::size_t>(offset), static_cast<std::size_t>(length));
    return Ok{};
  }

 private:
  Bytes data_;
};

// Appends to a file descriptor through a buffer of its own. Small writes (record headers, indexes,
// small messages) gather in the buffer; a large one goes to the kernel straight from the caller's
// bytes, in one writev() with what the buffer holds: no copy, one system call.
class FileSink final : public ByteSink {
 public:
  explicit FileSink(int fd) : fd_(fd) {
    struct stat st {};
    seekable_ = ::fstat(fd_, &st) == 0 && S_ISREG(st.st_mode);
    buffer_.reserve(kBuffer);
  }
  ~FileSink() override {
    if (fd_ >= 0) ::close(fd_);
  }
  Status write(ByteView data) override {
    if (fd_ < 0) return Error{"file closed", ErrorCode::NotOpen};
    if (buffer_.size() + data.size() <= kBuffer) {
      buffer_.insert(buffer_.end(), data.begin(), data.end());
      return Ok{};
    }
    if (data.size() < kDirect) {
      if (Status s = flush(); !s.ok()) return s;
      buffer_.assign(data.begin(), data.end());
      return Ok{};
    }
    Status s = write_fully(buffer_.size() + data.size(), [&](std::size_t done) {
      const std::size_t skip = std::min(done, buffer_.size());
      iovec rest[2] = {{buffer_.data() + skip, buffer_.size() - skip},
                       {const_cast<std::byte*>(data.data()) + (done - skip), data.size() - (done - skip)}};
      const int first = rest[0].iov_len == 0 ? 1 : 0;
      return ::writev(fd_, rest + first, 2 - first);
    });
    buffer_.clear();
    return s;
  }
  Status flush() override {
    if (fd_ < 0) return Ok{};
    Status s = write_fully(buffer_.size(), [&](std::size_t done) {
      return ::write(fd_, buffer_.data() + done, buffer_.size() - done);
    });
    buffer_.clear();
    return s;
  }
  Status close() override {
    if (fd_ < 0) return Ok{};
    Status s = flush();
    const int rc = ::close(fd_);
    fd_ = -1;
    if (s.ok() && rc != 0) {
      return Error{std::string("close failed: ") + std::strerror(errno), ErrorCode::IoError};
    }
    return s;
  }
  const Bytes& buffer() const override { return empty_; }
  bool seekable() const override { return seekable_; }
  Status write_at(std::uint64_t offset, ByteView data) override {
    if (fd_ < 0) return Error{"file closed", ErrorCode::NotOpen};
    if (!seekable_) return Error{"write_at on a file that cannot seek", ErrorCode::IoError};
    // The bytes may still sit in the buffer. pwrite() leaves the file position (where write()
    // appends next) where it is.
    if (Status s = flush(); !s.ok()) return s;
    return write_fully(data.size(), [&](std::size_t done) {
      return ::pwrite(fd_, data.data() + done, data.size() - done, static_cast<off_t>(offset + done));
    });
  }

 private:
  static constexpr std::size_t kBuffer = 64 * 1024;
  static constexpr std::size_t kDirect = 16 * 1024;  // writes from this size bypass the buffer

  // Calls `put(done)` (a write, writev or pwrite of what remains after `done` bytes, returning its
  // result) until `size` bytes are out, retrying on EINTR. A failure says how many bytes the file
  // holds (ENOSPC, EDQUOT, EFBIG, EIO).
  template <class Put>
  Status write_fully(std::size_t size, Put put) {
    std::size_t done = 0;
    while (done < size) {  // bounded: every pass writes at least one byte or returns
      const ssize_t n = put(done);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) {
        const int error = errno != 0 ? errno : EIO;
        struct stat st {};
        const std::string held =
            ::fstat(fd_, &st) == 0 ? " after " + std::to_string(st.st_size) + " bytes" : std::string();
        return Error{"write failed" + held + ": " + std::strerror(error), ErrorCode::IoError};
      }
      done += static_cast<std::size_t>(n);
    }
    return Ok{};
  }

  int fd_ = -1;
  bool seekable_ = false;
  Bytes buffer_;
  Bytes empty_;
};

class BufferSink final : public ByteSink {
 public:
  Status write(ByteView data) override {
    data_.insert(data_.end(), data.begin(), data.end());
    return Ok{};
  }
  Status flush() override { return Ok{}; }
  Status close() override { return Ok{}; }
  const Bytes& buffer() const override { return data_; }
  bool seekable() const override { return true; }
  Status write_at(std::uint64_t offset, ByteView data) override {
    if (offset > data_.size() || data.size() > data_.size() - offset) {
      return Error{"write_at past the end of the buffer", ErrorCode::InvalidArgument};
    }
    std::copy(data.begin(), data.end(), data_.begin() + static_cast<std::ptrdiff_t>(offset));
    return Ok{};
  }

 private:
  Bytes data_;
};

}  // namespace
}  // namespace detail

Result<std::unique_ptr<ByteSource>> open_file_source(const std::string& path) {
  detail::FilePtr file(std::fopen(path.c_str(), "rb"));
  if (!file) return detail::io_error("cannot open", path);
  if (fseeko(file.get(), 0, SEEK_END) != 0) return detail::io_error("cannot seek", path);
  const off_t size = ftello(file.get());
  if (size < 0 || fseeko(file.get(), 0, SEEK_SET) != 0) return detail::io_error("cannot size", path);
  return std::unique_ptr<ByteSource>(
      std::make_unique<detail::FileSource>(std::move(file), static_cast<std::uint64_t>(size)));
}

std::unique_ptr<ByteSource> make_buffer_source(Bytes data) {
  return std::make_unique<detail::BufferSource>(std::move(data));
}

Status ViewSource::read(std::uint64_t offset, std::uint64_t length, ByteView& out) {
  if (offset > data_.size() || length > data_.size() - offset) {
    return detail::out_of_range(offset, length, size());
  }
  out = data_.subspan(static_cast<std::size_t>(offset), static_cast<std::size_t>(length));
  return Ok{};
}

namespace detail {

Result<std::unique_ptr<ByteSink>> open_file_sink(const std::string& path) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);  // as fopen "wb"
  if (fd < 0) return io_error("cannot create", path);
  return std::unique_ptr<ByteSink>(std::make_unique<FileSink>(fd));
}

std::unique_ptr<ByteSink> make_buffer_sink() {
  return std::make_unique<BufferSink>();
}

}  // namespace detail
}  // namespace rbsim::mcap
