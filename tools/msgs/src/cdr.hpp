// Little-endian XCDR1 writer behind the 4-byte encapsulation header (CDR_LE = 00 01 00 00).
// Like Cyclone DDS (and the XTypes/RTPS rule it follows), the finished message is zero-padded to a
// multiple of 4 bytes and the pad count goes into the low bits of the options (header byte 3), so
// the bytes are identical to what Cyclone serialises for the same sample.
#pragma once

#include <algorithm>
#include <bit>
#include <cstring>
#include <string_view>

#include "rbsim/msgs.hpp"

namespace rbsim::msgs::detail {

static_assert(std::endian::native == std::endian::little,
              "the CDR writer copies native little-endian values");

class CdrWriter {
 public:
  // Clears `out` (keeping its capacity) and writes the encapsulation header.
  explicit CdrWriter(Bytes& out) : out_(out) {
    out_.assign(4, std::byte{0});
    out_[1] = std::byte{1};
    n_ = 4;
  }
  // Finishes the message when the encoder is done with it: pads to 4, records the pad count.
  ~CdrWriter() {
    out_.resize(n_);  // drop the unused workspace past the last value written
    const std::size_t pad = (4 - out_.size() % 4) % 4;
    out_.resize(out_.size() + pad, std::byte{0});
    out_[3] = static_cast<std::byte>(pad);
  }
  CdrWriter(const CdrWriter&) = delete;
  CdrWriter& operator=(const CdrWriter&) = delete;
  void u8(std::uint8_t v) { put(v); }
  void boolean(bool v) { put(static_cast<std::uint8_t>(v ? 1 : 0)); }
  void u16(std::uint16_t v) { put(v); }
  void i32(std::int32_t v) { put(v); }
  void u32(std::uint32_t v) { put(v); }
  void u64(std::uint64_t v) { put(v); }
  void i64(std::int64_t v) { put(v); }
  void f32(float v) { put(v); }
  void f64(double v) { put(v); }
  void string(std::string_view s) {
    u32(static_cast<std::uint32_t>(s.size() + 1));
    raw(s.data(), s.size());
    put(std::uint8_t{0});
  }
  void sequence_length(std::size_t n) { u32(static_cast<std::uint32_t>(n)); }
  void time(const Time& t) {
    i32(t.sec);
    u32(t.nanosec);
  }
  void header(const Time& stamp, std::string_view frame_id) {
    time(stamp);
    string(frame_id);
  }

 private:
  // The vector serves as workspace: values go to [n_, ...) and out_ grows geometrically (within its
  // capacity first), so a value costs a bounds check and a copy instead of a resize each; the
  // destructor trims out_ to n_. Bytes are the same as appending value by value.
  template <class T>
  void put(T v) {
    // Primitives align to their own size, counted from the end of the encapsulation header.
    static_assert(std::has_single_bit(sizeof(T)));
    const std::size_t pad = (0 - (n_ - 4)) & (sizeof(T) - 1);
    std::byte* p = room(pad + sizeof(T));
    std::memset(p, 0, pad);
    std::memcpy(p + pad, &v, sizeof(T));
  }
  void raw(const void* p, std::size_t n) {
    if (n == 0) return;
    std::memcpy(room(n), p, n);
  }
  // Pointer to `n` writable bytes at the end of the message; advances the end past them.
  std::byte* room(std::size_t n) {
    if (n_ + n > out_.size()) grow(n_ + n);
    std::byte* p = out_.data() + n_;
    n_ += n;
    return p;
  }
  void grow(std::size_t need) {
    const std::size_t doubled = std::max<std::size_t>(2 * out_.size(), 256);
    out_.resize(std::max(need, out_.capacity() > need ? std::min(doubled, out_.capacity()) : doubled));
  }
  Bytes& out_;
  std::size_t n_ = 0;  // bytes of the message written so far
};

}  // namespace rbsim::msgs::detail
