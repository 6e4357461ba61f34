// Byte buffers written as literals in tests: rbsim::Bytes holds std::byte, which neither a
// character nor an integer converts to implicitly.
//   bytes_of("PK\x03\x04")       the characters of a string (embedded NULs need a string_view)
//   bytes({0x89, 'M', 'C', 0})   small integers and characters, each one byte
#pragma once

#include <cstddef>
#include <initializer_list>
#include <string>
#include <string_view>

#include "rbsim/bytes.hpp"

namespace rbsim {

inline Bytes bytes_of(std::string_view s) {
  Bytes out(s.size());
  for (std::size_t i = 0; i < s.size(); ++i) out[i] = static_cast<std::byte>(s[i]);
  return out;
}

inline Bytes bytes(std::initializer_list<unsigned char> values) {
  Bytes out;
  out.reserve(values.size());
  for (unsigned char v : values) out.push_back(std::byte{v});
  return out;
}

// The bytes as characters, for comparing with text.
inline std::string text_of(ByteView b) {
  return {reinterpret_cast<const char*>(b.data()), b.size()};
}

}  // namespace rbsim
