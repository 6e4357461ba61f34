#include "io.hpp"

#include <cerrno>
#include <cstring>

namespace rbsim::mcap::detail {
namespace {

Status io_error(const std::string& what, const std::string& path) {
  return Status::Error(StatusCode::IoError, what + " '" + path + "': " + std::strerror(errno));
}

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};
using FilePtr = std::unique_ptr<std::FILE, FileCloser>;

class FileSource final : public Source {
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
      return Status::Error(StatusCode::IoError, std::string("seek failed: ") + std::strerror(errno));
    }
    const std::size_t got = std::fread(buffer_.data(), 1, n, file_.get());
    position_ = offset + got;
    if (got != n) {
      position_ = UINT64_MAX;
      return Status::Error(StatusCode::IoError, "short read at offset " + std::to_string(offset));
    }
    out = ByteView(buffer_).first(n);
    return Status::Ok();
  }

 private:
  FilePtr file_;
  std::uint64_t size_ = 0;
  std::uint64_t position_ = 0;
  Bytes buffer_;
};

class BufferSource final : public Source {
 public:
  explicit BufferSource(Bytes data) : data_(std::move(data)) {}
  std::uint64_t size() const override { return data_.size(); }
  Status read(std::uint64_t offset, std::uint64_t length, ByteView& out) override {
    if (offset > data_.size() || length > data_.size() - offset) return out_of_range(offset, length, size());
    out = ByteView(data_).subspan(static_cast<std::size_t>(offset), static_cast<std::size_t>(length));
    return Status::Ok();
  }

 private:
  Bytes data_;
};

class FileSink final : public Sink {
 public:
  explicit FileSink(FilePtr file) : file_(std::move(file)) {}
  Status write(ByteView data) override {
    if (!file_) return Status::Error(StatusCode::NotOpen, "file closed");
    if (std::fwrite(data.data(), 1, data.size(), file_.get()) != data.size()) {
      return Status::Error(StatusCode::IoError, std::string("write failed: ") + std::strerror(errno));
    }
    return Status::Ok();
  }
  Status flush() override {
    if (file_ && std::fflush(file_.get()) != 0) {
      return Status::Error(StatusCode::IoError, std::string("flush failed: ") + std::strerror(errno));
    }
    return Status::Ok();
  }
  Status close() override {
    if (!file_) return Status::Ok();
    const int rc = std::fclose(file_.release());
    if (rc != 0) {
      return Status::Error(StatusCode::IoError, std::string("close failed: ") + std::strerror(errno));
    }
    return Status::Ok();
  }
  const Bytes& buffer() const override { return empty_; }

 private:
  FilePtr file_;
  Bytes empty_;
};

class BufferSink final : public Sink {
 public:
  Status write(ByteView data) override {
    data_.insert(data_.end(), data.begin(), data.end());
    return Status::Ok();
  }
  Status flush() override { return Status::Ok(); }
  Status close() override { return Status::Ok(); }
  const Bytes& buffer() const override { return data_; }

 private:
  Bytes data_;
};

}  // namespace

Result<std::unique_ptr<Source>> open_file_source(const std::string& path) {
  FilePtr file(std::fopen(path.c_str(), "rb"));
  if (!file) return io_error("cannot open", path);
  if (fseeko(file.get(), 0, SEEK_END) != 0) return io_error("cannot seek", path);
  const off_t size = ftello(file.get());
  if (size < 0 || fseeko(file.get(), 0, SEEK_SET) != 0) return io_error("cannot size", path);
  return std::unique_ptr<Source>(
      std::make_unique<FileSource>(std::move(file), static_cast<std::uint64_t>(size)));
}

std::unique_ptr<Source> make_buffer_source(Bytes data) {
  return std::make_unique<BufferSource>(std::move(data));
}

Result<std::unique_ptr<Sink>> open_file_sink(const std::string& path) {
  FilePtr file(std::fopen(path.c_str(), "wb"));
  if (!file) return io_error("cannot create", path);
  return std::unique_ptr<Sink>(std::make_unique<FileSink>(std::move(file)));
}

std::unique_ptr<Sink> make_buffer_sink() {
  return std::make_unique<BufferSink>();
}

}  // namespace rbsim::mcap::detail
