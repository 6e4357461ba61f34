// Little-endian primitives of the MCAP wire format (spec: Serialization).
#pragma once

#include <cstring>
#include <limits>

#include "rbsim/mcap.hpp"
#include "rbsim/mcap_records.hpp"

namespace rbsim::mcap::detail {

// " at offset N", the place of every read error.
inline std::string at(std::uint64_t offset) {
  return " at offset " + std::to_string(offset);
}

// Bounds-checked reader over one record's content. Every length prefix is checked against the
// bytes that remain, so a corrupt length can neither overrun nor cause a large allocation.
class Cursor {
 public:
  explicit Cursor(ByteView data) : data_(data) {}

  std::size_t remaining() const { return data_.size() - pos_; }
  std::size_t position() const { return pos_; }

  bool u8(std::uint8_t& v) { return fixed(v); }
  bool u16(std::uint16_t& v) { return fixed(v); }
  bool u32(std::uint32_t& v) { return fixed(v); }
  bool u64(std::uint64_t& v) { return fixed(v); }

  bool view(std::uint64_t n, ByteView& out) {
    if (n > remaining()) return false;
    out = data_.subspan(pos_, static_cast<std::size_t>(n));
    pos_ += static_cast<std::size_t>(n);
    return true;
  }
  bool string(std::string& out) {
    ByteView v;
    if (!prefixed32(v)) return false;
    out.assign(reinterpret_cast<const char*>(v.data()), v.size());
    return true;
  }
  bool bytes32(Bytes& out) {
    ByteView v;
    if (!prefixed32(v)) return false;
    out.assign(v.begin(), v.end());
    return true;
  }
  bool bytes64(Bytes& out) {
    std::uint64_t n = 0;
    ByteView v;
    if (!u64(n) || !view(n, v)) return false;
    out.assign(v.begin(), v.end());
    return true;
  }
  bool rest(Bytes& out) {
    ByteView v;
    (void)view(remaining(), v);
    out.assign(v.begin(), v.end());
    return true;
  }
  // Map<string, string>: uint32 byte length, then key/value strings.
  bool string_map(KeyValueMap& out) {
    ByteView v;
    if (!prefixed32(v)) return false;
    Cursor inner(v);
    while (inner.remaining() > 0) {
      std::string key, value;
      if (!inner.string(key) || !inner.string(value)) return false;
      out.insert_or_assign(std::move(key), std::move(value));
    }
    return true;
  }
  // Map<uint16, uint64>.
  bool id_map(std::map<std::uint16_t, std::uint64_t>& out) {
    ByteView v;
    if (!prefixed32(v)) return false;
    Cursor inner(v);
    while (inner.remaining() > 0) {
      std::uint16_t key = 0;
      std::uint64_t value = 0;
      if (!inner.u16(key) || !inner.u64(value)) return false;
      out.insert_or_assign(key, value);
    }
    return true;
  }
  // Array<Tuple<Timestamp, uint64>>.
  bool time_offsets(std::vector<std::pair<Timestamp, std::uint64_t>>& out) {
    ByteView v;
    if (!prefixed32(v) || v.size() % 16 != 0) return false;
    Cursor inner(v);
    out.reserve(v.size() / 16);
    while (inner.remaining() > 0) {
      std::uint64_t t = 0, o = 0;
      (void)(inner.u64(t) && inner.u64(o));
      out.emplace_back(t, o);
    }
    return true;
  }

 private:
  template <typename T>
  bool fixed(T& v) {
    if (remaining() < sizeof(T)) return false;
    T out = 0;
    for (std::size_t i = 0; i < sizeof(T); ++i)
      out = static_cast<T>(out | static_cast<T>(std::to_integer<T>(data_[pos_ + i]) << (8 * i)));
    v = out;
    pos_ += sizeof(T);
    return true;
  }
  bool prefixed32(ByteView& out) {
    std::uint32_t n = 0;
    return u32(n) && view(n, out);
  }

  ByteView data_;
  std::size_t pos_ = 0;
};

template <typename T>
inline void put(Bytes& out, T v) {
  for (std::size_t i = 0; i < sizeof(T); ++i) out.push_back(static_cast<std::byte>(v >> (8 * i)));
}
inline void put_u8(Bytes& out, std::uint8_t v) {
  out.push_back(std::byte{v});
}
inline void put_u16(Bytes& out, std::uint16_t v) {
  put(out, v);
}
inline void put_u32(Bytes& out, std::uint32_t v) {
  put(out, v);
}
inline void put_u64(Bytes& out, std::uint64_t v) {
  put(out, v);
}
inline void put_raw(Bytes& out, ByteView v) {
  out.insert(out.end(), v.begin(), v.end());
}
inline ByteView as_bytes(std::string_view s) {
  return {reinterpret_cast<const std::byte*>(s.data()), s.size()};
}
inline void put_string(Bytes& out, std::string_view s) {
  put_u32(out, static_cast<std::uint32_t>(s.size()));
  put_raw(out, as_bytes(s));
}
inline void put_bytes32(Bytes& out, ByteView v) {
  put_u32(out, static_cast<std::uint32_t>(v.size()));
  put_raw(out, v);
}
inline void put_bytes64(Bytes& out, ByteView v) {
  put_u64(out, v.size());
  put_raw(out, v);
}
// Writes a uint32 length placeholder; finish_prefix() patches it once the body is appended.
inline std::size_t begin_prefix(Bytes& out) {
  put_u32(out, 0);
  return out.size();
}
inline void finish_prefix(Bytes& out, std::size_t body_start) {
  const auto n = static_cast<std::uint32_t>(out.size() - body_start);
  for (std::size_t i = 0; i < 4; ++i) out[body_start - 4 + i] = static_cast<std::byte>(n >> (8 * i));
}
inline void put_string_map(Bytes& out, const KeyValueMap& map) {
  const std::size_t start = begin_prefix(out);
  for (const auto& [k, v] : map) {
    put_string(out, k);
    put_string(out, v);
  }
  finish_prefix(out, start);
}
inline void put_id_map(Bytes& out, const std::map<std::uint16_t, std::uint64_t>& map) {
  put_u32(out, static_cast<std::uint32_t>(map.size() * 10));
  for (const auto& [k, v] : map) {
    put_u16(out, k);
    put_u64(out, v);
  }
}

inline constexpr std::size_t kRecordPrefix = RecordReader::kPrefixSize;
inline constexpr std::size_t kFooterContent = 20;
inline constexpr std::size_t kFooterRecord = kRecordPrefix + kFooterContent;

// parse_record for a Chunk without copying its records: `chunk` gets every other field, `records`
// views them in `content`. The same checks and error as parse_record.
Status parse_chunk_view(ByteView content, Chunk& chunk, ByteView& records);
// parse_record for a Message into `message`, whose data buffer is reused (no allocation once it is
// large enough). The same checks and error as parse_record.
Status parse_message_into(ByteView content, Message& message);

}  // namespace rbsim::mcap::detail
