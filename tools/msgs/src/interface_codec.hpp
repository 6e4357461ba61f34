// The codec skeleton the interface codecs share (interfaces.cpp, simulation_interfaces.cpp): the
// type's name in an error, strings, and one encode/decode driver around a type's put()/get().
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "cdr.hpp"
#include "cdr_reader.hpp"

namespace rbsim::msgs::detail {

// The fewest bytes one string can take on the wire (u32 length + the NUL): what a sequence of
// strings' length is checked against (Reader::length), so a huge length in a short message fails
// before anything is allocated.
constexpr std::size_t kMinString = 5;

inline void put_strings(CdrWriter& w, const std::vector<std::string>& v) {
  w.sequence_length(v.size());
  for (const std::string& s : v) w.string(s);
}
inline void get_strings(Reader& r, std::vector<std::string>& v) {
  v.resize(r.length(kMinString));
  for (std::string& s : v) s = r.string();
}

// unique_identifier_msgs/msg/UUID (an action's goal id): 16 octets.
inline void put_uuid(CdrWriter& w, const std::array<std::uint8_t, 16>& id) {
  for (const std::uint8_t b : id) w.u8(b);
}
inline void get_uuid(Reader& r, std::array<std::uint8_t, 16>& id) {
  for (std::uint8_t& b : id) b = r.get<std::uint8_t>();
}

// "rcl_interfaces/msg/Parameter", or "std_srvs/srv/Trigger request" for a service half.
template <class T>
std::string name_of(std::string_view half) {
  if constexpr (requires { T::kType; }) {
    return std::string(T::kType);
  } else {
    return std::string(T::kService) + std::string(half);
  }
}

// `put(w, m)` writes m's fields (the caller's put: the codecs' own overloads live in unnamed
// namespaces, which argument-dependent lookup does not search).
template <class T, class Put>
void encode_message(const T& m, Bytes& out, Put put) {
  CdrWriter w(out);
  put(w, m);
}
template <class T, class Get>
Status decode_message(std::span<const std::byte> cdr, T& out, std::string_view half, Get get) {
  Reader r(cdr);
  if (!r.ok()) {
    return Error{"malformed " + name_of<T>(half) + ": not plain little-endian CDR (a 4-byte header 00 01)",
                 ErrorCode::Malformed};
  }
  out = T{};
  get(r, out);
  if (!r.ok()) {
    return Error{"malformed or truncated " + name_of<T>(half) + ": bad or missing data at byte " +
                     std::to_string(r.pos()) + " of " + std::to_string(cdr.size()),
                 ErrorCode::Truncated};
  }
  return Ok{};
}

}  // namespace rbsim::msgs::detail

// Defines encode() and decode() of type T (declared in its public header) on the put() and get()
// overloads in scope where it is expanded; `half` names a service half in errors (" request").
#define RBSIM_DEFINE_CODEC(T, half)                                                    \
  void encode(const T& message, Bytes& out) {                                          \
    detail::encode_message(message, out, [](CdrWriter& w, const T& m) { put(w, m); }); \
  }                                                                                    \
  Status decode(std::span<const std::byte> cdr, T& out) {                              \
    return detail::decode_message(cdr, out, half, [](Reader& r, T& m) { get(r, m); }); \
  }
