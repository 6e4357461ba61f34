#include "codec.hpp"

#include <lz4frame.h>
#include <zstd.h>

#include <algorithm>
#include <cstdio>

namespace rbsim::mcap {
namespace detail {

struct Compressor::Impl {
  Compression compression = Compression::None;
  int level = 0;
  ZSTD_CCtx* zstd = nullptr;  // reused across chunks: creating one costs more than a small chunk
  // Output buffer, grown when a bound exceeds it and never value-initialised (a std::vector
  // resized up to the bound for every chunk would zero what the last one's shrink gave back).
  std::unique_ptr<std::byte[]> buffer;
  std::size_t capacity = 0;
  std::byte* room(std::size_t n) {
    if (n > capacity) {
      buffer.reset(new std::byte[n]);
      capacity = n;
    }
    return buffer.get();
  }
};

Compressor::Compressor(Compression compression, int level) : impl_(std::make_unique<Impl>()) {
  impl_->compression = compression;
  impl_->level = level;
  if (compression == Compression::Zstd) impl_->zstd = ZSTD_createCCtx();
}

Compressor::~Compressor() {
  ZSTD_freeCCtx(impl_->zstd);
}

Status Compressor::compress(ByteView in, ByteView& out) {
  switch (impl_->compression) {
    case Compression::None:
      out = in;
      return Ok{};
    case Compression::Zstd: {
      if (impl_->zstd == nullptr) return Error{"out of memory for zstd context", ErrorCode::IoError};
      const std::size_t bound = ZSTD_compressBound(in.size());
      std::byte* dst = impl_->room(bound);
      // Level 0 is the MCAP C++ library's default for zstd chunks, 1 (zstd's own default is 3).
      // scripts/bench-mcap prints what levels 3 and -3 cost and save against it.
      const int level = impl_->level == 0 ? 1 : impl_->level;
      const std::size_t n = ZSTD_compressCCtx(impl_->zstd, dst, bound, in.data(), in.size(), level);
      if (ZSTD_isError(n)) {
        return Error{std::string("zstd: ") + ZSTD_getErrorName(n), ErrorCode::IoError};
      }
      out = ByteView(dst, n);
      return Ok{};
    }
    case Compression::Lz4: {
      LZ4F_preferences_t prefs{};
      prefs.compressionLevel = impl_->level;
      const std::size_t bound = LZ4F_compressFrameBound(in.size(), &prefs);
      std::byte* dst = impl_->room(bound);
      const std::size_t n = LZ4F_compressFrame(dst, bound, in.data(), in.size(), &prefs);
      if (LZ4F_isError(n)) {
        return Error{std::string("lz4: ") + LZ4F_getErrorName(n), ErrorCode::IoError};
      }
      out = ByteView(dst, n);
      return Ok{};
    }
  }
  return Error{"unknown compression", ErrorCode::UnsupportedCompression};
}

ChunkWorker::ChunkWorker(Compression compression, int level, bool crc)
    : compressor_(compression, level),
      compression_(compression),
      with_crc_(crc),
      thread_([this] { run(); }) {}

ChunkWorker::~ChunkWorker() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  cv_.notify_all();
  thread_.join();
}

void ChunkWorker::submit() {
  pending_ = true;
  finished_.store(false, std::memory_order_relaxed);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    start_ = true;
  }
  cv_.notify_all();
}

Status ChunkWorker::wait() {
  std::unique_lock<std::mutex> lock(mutex_);
  cv_.wait(lock, [this] { return finished_.load(std::memory_order_relaxed); });
  return status_;
}

ByteView ChunkWorker::payload() const {
  return compression_ == Compression::None ? ByteView(records_) : compressed_;
}

void ChunkWorker::release() {
  records_.clear();
  pending_ = false;
}

void ChunkWorker::run() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    cv_.wait(lock, [this] { return start_ || stop_; });
    if (stop_) return;
    start_ = false;
    lock.unlock();
    crc_ = with_crc_ ? crc32(records_) : 0;
    Status s = compression_ == Compression::None ? Ok{} : compressor_.compress(records_, compressed_);
    lock.lock();
    status_ = std::move(s);
    finished_.store(true, std::memory_order_release);
    cv_.notify_all();
  }
}

Result<Compression> compression_from_name(std::string_view name) {
  if (name.empty()) return Compression::None;
  if (name == "lz4") return Compression::Lz4;
  if (name == "zstd") return Compression::Zstd;
  return Error{"unsupported chunk compression '" + std::string(name) + "'",
               ErrorCode::UnsupportedCompression};
}

}  // namespace detail

namespace {

Status decompress_error(std::string_view codec, const char* what) {
  return Error{std::string(codec) + ": " + what, ErrorCode::DecompressionFailed};
}

// Output grows with what the decoder really produces (never to a declared size up front), and
// stops one byte past `expected`: a corrupt uncompressed_size cannot trigger a huge allocation.
class GrowingOutput {
 public:
  GrowingOutput(Bytes& out, std::uint64_t expected, std::size_t input_size) : out_(out) {
    limit_ = expected < SIZE_MAX ? expected + 1 : expected;
    out_.resize(static_cast<std::size_t>(
        std::min<std::uint64_t>(limit_, std::max<std::size_t>(input_size * 4, 4096))));
  }
  // Makes room for more output; false once the output already exceeds `expected`.
  bool grow_if_full() {
    if (produced < out_.size()) return true;
    if (out_.size() >= limit_) return false;
    out_.resize(static_cast<std::size_t>(std::min<std::uint64_t>(limit_, out_.size() * 2)));
    return true;
  }
  std::byte* data() { return out_.data() + produced; }
  std::size_t room() const { return out_.size() - produced; }
  void finish() { out_.resize(produced); }

  std::size_t produced = 0;

 private:
  Bytes& out_;
  std::uint64_t limit_ = 0;
};

Status zstd_decompress(ZSTD_DCtx* ctx, ByteView in, std::uint64_t expected, Bytes& out) {
  GrowingOutput o(out, expected, in.size());
  ZSTD_inBuffer ib{in.data(), in.size(), 0};
  std::size_t hint = 1;
  while (ib.pos < ib.size || hint != 0) {
    if (!o.grow_if_full()) break;  // more output than declared: reported by the size check
    ZSTD_outBuffer ob{o.data(), o.room(), 0};
    const std::size_t before_in = ib.pos;
    hint = ZSTD_decompressStream(ctx, &ob, &ib);
    if (ZSTD_isError(hint)) return decompress_error("zstd", ZSTD_getErrorName(hint));
    o.produced += ob.pos;
    if (hint != 0 && ob.pos == 0 && ib.pos == before_in) return decompress_error("zstd", "truncated frame");
  }
  o.finish();
  return Ok{};
}

Status lz4_decompress(LZ4F_dctx* ctx, ByteView in, std::uint64_t expected, Bytes& out) {
  GrowingOutput o(out, expected, in.size());
  std::size_t consumed = 0;
  std::size_t hint = 1;
  while (consumed < in.size() || hint != 0) {
    if (!o.grow_if_full()) break;
    std::size_t dst = o.room();
    std::size_t src = in.size() - consumed;
    hint = LZ4F_decompress(ctx, o.data(), &dst, in.data() + consumed, &src, nullptr);
    if (LZ4F_isError(hint)) return decompress_error("lz4", LZ4F_getErrorName(hint));
    o.produced += dst;
    consumed += src;
    if (hint != 0 && dst == 0 && src == 0) return decompress_error("lz4", "truncated frame");
  }
  o.finish();
  return Ok{};
}

}  // namespace

std::string_view to_string(Compression compression) {
  switch (compression) {
    case Compression::Lz4:
      return "lz4";
    case Compression::Zstd:
      return "zstd";
    case Compression::None:
      break;
  }
  return "";
}

namespace detail {

struct Decompressor::Impl {
  ZSTD_DCtx* zstd = nullptr;  // created on first use, reset before each chunk
  LZ4F_dctx* lz4 = nullptr;
};

Decompressor::Decompressor() : impl_(std::make_unique<Impl>()) {}

Decompressor::~Decompressor() {
  ZSTD_freeDCtx(impl_->zstd);
  if (impl_->lz4 != nullptr) LZ4F_freeDecompressionContext(impl_->lz4);
}

Status Decompressor::decompress(const Chunk& chunk, ByteView records, Bytes& out, bool verify_crc) {
  auto compression = compression_from_name(chunk.compression);
  if (!compression.ok()) return compression.error();
  Status status;
  switch (*compression) {
    case Compression::None:
      out.assign(records.begin(), records.end());
      break;
    case Compression::Zstd:
      if (impl_->zstd == nullptr) {
        impl_->zstd = ZSTD_createDCtx();
        if (impl_->zstd == nullptr) return decompress_error("zstd", "cannot allocate context");
      } else {
        ZSTD_DCtx_reset(impl_->zstd, ZSTD_reset_session_only);  // after an error, too
      }
      status = zstd_decompress(impl_->zstd, records, chunk.uncompressed_size, out);
      break;
    case Compression::Lz4:
      if (impl_->lz4 == nullptr) {
        if (LZ4F_isError(LZ4F_createDecompressionContext(&impl_->lz4, LZ4F_VERSION))) {
          impl_->lz4 = nullptr;
          return decompress_error("lz4", "cannot allocate context");
        }
      } else {
        LZ4F_resetDecompressionContext(impl_->lz4);
      }
      status = lz4_decompress(impl_->lz4, records, chunk.uncompressed_size, out);
      break;
  }
  if (!status.ok()) return status;
  if (out.size() != chunk.uncompressed_size) {
    return Error{"chunk decompresses to " + std::to_string(out.size()) + " bytes, header says " +
                     std::to_string(chunk.uncompressed_size),
                 ErrorCode::Malformed};
  }
  if (verify_crc && chunk.uncompressed_crc != 0) {
    const std::uint32_t crc = crc32(out);
    if (crc != chunk.uncompressed_crc) {
      return Error{
          "chunk CRC mismatch: computed " + crc_text(crc) + ", stored " + crc_text(chunk.uncompressed_crc),
          ErrorCode::CrcMismatch};
    }
  }
  return Ok{};
}

}  // namespace detail

Status decompress_chunk(const Chunk& chunk, Bytes& out, bool verify_crc) {
  detail::Decompressor decompressor;
  return decompressor.decompress(chunk, chunk.records, out, verify_crc);
}

ChunkDecompressor::ChunkDecompressor() : impl_(std::make_unique<detail::Decompressor>()) {}
ChunkDecompressor::~ChunkDecompressor() = default;

Status ChunkDecompressor::decompress(const Chunk& chunk, Bytes& out, bool verify_crc) {
  return impl_->decompress(chunk, chunk.records, out, verify_crc);
}

bool parse_compression(std::string_view name, Compression& out) {
  if (name == "zstd") return out = Compression::Zstd, true;
  if (name == "lz4") return out = Compression::Lz4, true;
  if (name == "none") return out = Compression::None, true;
  return false;
}

std::string check_compression_level(Compression compression, int level) {
  const auto range = [level](int lo, int hi, const char* codec) -> std::string {
    if (level >= lo && level <= hi) return {};
    return "compression level " + std::to_string(level) + " is outside " + codec + "'s " +
           std::to_string(lo) + ".." + std::to_string(hi);
  };
  switch (compression) {
    case Compression::Zstd:
      return range(-50, 22, "zstd");
    case Compression::Lz4:
      return range(0, 12, "lz4");
    case Compression::None:
      return level == 0 ? std::string() : "a compression level needs --compression zstd or lz4";
  }
  return "unknown compression";
}

std::string crc_text(std::uint32_t crc) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%08x", crc);
  return buf;
}

}  // namespace rbsim::mcap
