// The sticky-failure reader over msgs::CdrCursor shared by the typed decoders.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "rbsim/cdr.hpp"
#include "rbsim/msgs.hpp"

namespace rbsim::msgs::detail {

// The typed decoders' reader: the CDR cursor with a sticky failure (the first one stops every
// later read, which then return zeros). Users: the typed decoders (typed.cpp) and the service and
// parameter codecs (interfaces.cpp).
class Reader {
 public:
  explicit Reader(std::span<const std::byte> data) : ok_(CdrCursor::plain_header(data)), at_(data) {}
  bool ok() const { return ok_; }
  // The byte offset of the read that failed once !ok() (the cursor stops there), from the start.
  std::size_t pos() const { return at_.pos(); }
  // Marks the data malformed (a value the caller checked and refused).
  void fail() { ok_ = false; }
  template <class T>
  T get() {
    T v{};
    if (ok_ && !at_.read(v)) ok_ = false;
    return v;
  }
  std::string string() { return std::string(string_view()); }
  void skip_string() { (void)string_view(); }
  // A sequence length, bounded by the bytes left (every element takes at least `min_size`).
  std::uint32_t length(std::size_t min_size) {
    const auto n = get<std::uint32_t>();
    if (ok_ && static_cast<std::uint64_t>(n) * min_size > at_.remaining()) ok_ = false;
    return ok_ ? n : 0;
  }
  Vec2 vec2() {
    const double x = get<double>();
    return {x, get<double>()};
  }
  Color color() {
    Color c;
    c.r = get<float>();
    c.g = get<float>();
    c.b = get<float>();
    (void)get<float>();  // alpha
    return c;
  }
  Time time() {
    Time t;
    t.sec = get<std::int32_t>();
    t.nanosec = get<std::uint32_t>();
    return t;
  }

 private:
  std::string_view string_view() {
    std::string_view s;
    if (!ok_ || !at_.string(s)) ok_ = false;
    return s;
  }
  bool ok_;
  CdrCursor at_;  // used only while ok_ (the header checked)
};

}  // namespace rbsim::msgs::detail
