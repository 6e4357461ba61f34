// Little-endian CDR written by hand for tests of CDR readers: values aligned as CDR aligns them
// (to their size, counted from the end of the 4-byte encapsulation header), independently of
// rbsim's own writer, so a reader is checked against the rule rather than against the writer.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "rbsim/msgs.hpp"

namespace rbsim::test {

struct Cdr {
  msgs::Bytes bytes{std::byte{0}, std::byte{1}, std::byte{0}, std::byte{0}};
  template <class T>
  Cdr& put(T v) {
    while ((bytes.size() - 4) % sizeof(T) != 0) bytes.push_back(std::byte{0});
    const auto* p = reinterpret_cast<const std::byte*>(&v);
    bytes.insert(bytes.end(), p, p + sizeof(T));
    return *this;
  }
  Cdr& str(const std::string& s) {
    put<std::uint32_t>(static_cast<std::uint32_t>(s.size() + 1));
    for (char c : s) bytes.push_back(static_cast<std::byte>(c));
    bytes.push_back(std::byte{0});
    return *this;
  }
};

}  // namespace rbsim::test
