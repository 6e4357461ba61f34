// The one CDR reading cursor: every reader of rbsim's CDR walks its bytes through it (the
// schema-driven and typed decoders, tools/msgs/src/decode.cpp and typed.cpp; rbsim check's layout
// counter and lockstep comparer, tools/check/src/layout.cpp and compare_values.cpp). The writer is
// msgs::detail::CdrWriter (tools/msgs/src/cdr.hpp).
//
// The rule it keeps: XCDR1, little endian, a 4-byte encapsulation header (00 01 = plain CDR_LE),
// every primitive aligned to its own size counted from the end of that header. Header-only and
// inline, so the comparer's per-value loop compiles to the same loads and compares as by hand.
#pragma once

#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <string_view>

namespace rbsim::msgs {

static_assert(std::endian::native == std::endian::little, "the CDR cursor loads native little-endian values");

class CdrCursor {
 public:
  static constexpr std::size_t kHeader = 4;  // the encapsulation header; offsets count from its end

  // True when `cdr` starts with the header of plain little-endian CDR (00 01), the one rbsim reads.
  static bool plain_header(std::span<const std::byte> cdr) {
    return cdr.size() >= kHeader && cdr[0] == std::byte{0} && cdr[1] == std::byte{1};
  }

  // A cursor at the first byte after the header. `cdr` must hold at least the header.
  explicit CdrCursor(std::span<const std::byte> cdr) : data_(cdr.data()), size_(cdr.size()), pos_(kHeader) {}

  std::size_t pos() const { return pos_; }                // from the start of the message
  std::size_t offset() const { return pos_ - kHeader; }   // from the end of the header
  std::size_t remaining() const { return size_ - pos_; }  // bytes after the cursor
  const std::byte* here() const { return data_ + pos_; }  // the byte at the cursor

  // Moves to the next multiple of `size` (a primitive's size) when `count` values of `size` bytes
  // follow there; false, the cursor unmoved, when they do not fit in the data.
  bool align(std::size_t size, std::uint64_t count = 1) {
    std::size_t pad = 0;
    if (!fits(size, count, pad)) return false;
    pos_ += pad;
    return true;
  }
  // align(size, count) and past the values; false, the cursor unmoved, when they do not fit.
  bool skip(std::size_t size, std::uint64_t count) {
    std::size_t pad = 0;
    if (!fits(size, count, pad)) return false;
    pos_ += pad + static_cast<std::size_t>(count) * size;
    return true;
  }
  // Past `n` bytes the caller has checked are there (n <= remaining()).
  void advance(std::size_t n) { pos_ += n; }

  // One primitive of `size` bytes, aligned, copied to `out`; false, the cursor unmoved, when it
  // does not fit.
  bool read(std::size_t size, void* out) {
    std::size_t pad = 0;
    if (!fits(size, 1, pad)) return false;
    std::memcpy(out, here() + pad, size);
    pos_ += pad + size;
    return true;
  }
  template <class T>
  bool read(T& out) {
    return read(sizeof(T), &out);
  }
  bool u32(std::uint32_t& out) { return read(out); }

  // A string: its u32 length (the terminating NUL counted, so at least 1), then its bytes, `out`
  // without the NUL. False when the length does not fit or is 0 or runs past the data.
  bool string(std::string_view& out) {
    std::uint32_t n = 0;
    if (!u32(n) || n == 0 || n > remaining()) return false;
    out = std::string_view(reinterpret_cast<const char*>(here()), n - 1);
    pos_ += n;
    return true;
  }

  // A native-endian value at `p`, unaligned (the comparer's loads of values it has bounds-checked).
  template <class T>
  static T load(const std::byte* p) {
    T v;
    std::memcpy(&v, p, sizeof(T));
    return v;
  }

 private:
  // The padding to the next multiple of `size`, and whether `count` values of `size` bytes fit
  // after it. One position update per read or skip, as the hot loops need.
  bool fits(std::size_t size, std::uint64_t count, std::size_t& pad) const {
    pad = (size - offset() % size) % size;
    const std::size_t left = remaining();
    return pad <= left && count <= (left - pad) / size;
  }

  const std::byte* data_;
  std::size_t size_;
  std::size_t pos_;
};

}  // namespace rbsim::msgs
