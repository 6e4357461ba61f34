// MessageDecoder::from_json: one message's JSON object to CDR, by the parsed schema (the inverse of
// to_json). Walks the schema, not the JSON, so what is written follows the type; the JSON only
// supplies values, and whatever it holds beyond the type's fields is an error.
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>

#include "cdr.hpp"
#include "rbsim/msgs.hpp"

namespace rbsim::msgs {

namespace {

using JsonValue = nlohmann::json;

// nlohmann's parser is iterative, but a value nested this deep is no message of ours either way:
// refusing it before parsing keeps every later step (destruction included) shallow.
constexpr int kMaxJsonDepth = 100;

bool too_deep(std::string_view text) {
  int depth = 0;
  bool in_string = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      if (c == '\\') {
        ++i;
      } else if (c == '"') {
        in_string = false;
      }
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > kMaxJsonDepth) return true;
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return false;
}

// The standard alphabet (RFC 4648), padding optional; rosbridge sends uint8[] this way.
bool base64_decode(std::string_view in, std::string& out) {
  out.clear();
  std::uint32_t acc = 0;
  int bits = 0;
  std::size_t pad = 0;
  for (const char c : in) {
    int v;
    if (c >= 'A' && c <= 'Z') {
      v = c - 'A';
    } else if (c >= 'a' && c <= 'z') {
      v = c - 'a' + 26;
    } else if (c >= '0' && c <= '9') {
      v = c - '0' + 52;
    } else if (c == '+') {
      v = 62;
    } else if (c == '/') {
      v = 63;
    } else if (c == '=') {
      ++pad;
      continue;
    } else {
      return false;
    }
    if (pad > 0) return false;  // data after padding
    acc = (acc << 6) | static_cast<std::uint32_t>(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out += static_cast<char>((acc >> bits) & 0xFF);
    }
  }
  return pad <= 2 && bits < 6;  // a lone 6-bit group is no byte
}

class Writer {
 public:
  Writer(const std::vector<MessageDecoder::Type>& types, detail::CdrWriter& out) : types_(types), out_(out) {}
  std::string error;

  // Message type `t` from `v` (null: absent, every field its zero value).
  bool message(std::size_t t, const JsonValue* v, std::string& path) {
    const MessageDecoder::Type& type = types_[t];
    if (v != nullptr) {
      if (!v->is_object()) return fail(path, "must be a JSON object (a " + type.name + ")");
      for (const auto& [key, value] : v->items()) {
        bool known = false;
        for (const MessageDecoder::Field& f : type.fields) known = known || f.name == key;
        if (!known) {
          append_name(path, key);
          return fail(path, "no such field in " + type.name);
        }
      }
    }
    for (const MessageDecoder::Field& f : type.fields) {
      const JsonValue* fv = nullptr;
      if (v != nullptr) {
        if (const auto it = v->find(f.name); it != v->end()) fv = &*it;
      }
      const std::size_t at = path.size();
      append_name(path, f.name);
      if (!field(f, fv, path)) return false;
      path.resize(at);
    }
    return true;
  }

 private:
  static void append_name(std::string& path, std::string_view name) {
    if (!path.empty()) path += '.';
    path += name;
  }

  bool field(const MessageDecoder::Field& f, const JsonValue* v, std::string& path) {
    using Array = MessageDecoder::Field::Array;
    if (f.array == Array::None) return element(f, v, path);
    const bool bytes = f.primitive >= 0 && f.scalar.kind == Scalar::Kind::UInt && f.scalar.size == 1;
    if (v != nullptr && v->is_string() && bytes)
      return byte_string(f, v->get_ref<const std::string&>(), path);
    if (v != nullptr && !v->is_array())
      return fail(path, bytes ? "must be an array (or a base64 string)" : "must be an array");
    const std::size_t given = v == nullptr ? 0 : v->size();
    std::size_t count = given;
    if (f.array == Array::Fixed) {
      if (v != nullptr && given != f.fixed_size)
        return fail(path, "must have exactly " + std::to_string(f.fixed_size) + " elements, has " +
                              std::to_string(given));
      count = f.fixed_size;
    } else {
      if (f.sequence_bound != 0 && given > f.sequence_bound)
        return fail(path, "must have at most " + std::to_string(f.sequence_bound) + " elements, has " +
                              std::to_string(given));
      out_.sequence_length(given);
    }
    for (std::size_t k = 0; k < count; ++k) {
      const std::size_t at = path.size();
      path += "[" + std::to_string(k) + "]";
      if (!element(f, v == nullptr ? nullptr : &(*v)[k], path)) return false;
      path.resize(at);
    }
    return true;
  }

  bool byte_string(const MessageDecoder::Field& f, const std::string& text, const std::string& path) {
    std::string raw;
    if (!base64_decode(text, raw)) return fail(path, "a string for bytes must be base64");
    if (f.array == MessageDecoder::Field::Array::Fixed) {
      if (raw.size() != f.fixed_size)
        return fail(path, "must have exactly " + std::to_string(f.fixed_size) + " elements, has " +
                              std::to_string(raw.size()) + " (base64)");
    } else {
      if (f.sequence_bound != 0 && raw.size() > f.sequence_bound)
        return fail(path, "must have at most " + std::to_string(f.sequence_bound) + " elements, has " +
                              std::to_string(raw.size()) + " (base64)");
      out_.sequence_length(raw.size());
    }
    for (const char c : raw) out_.u8(static_cast<std::uint8_t>(c));
    return true;
  }

  bool element(const MessageDecoder::Field& f, const JsonValue* v, std::string& path) {
    if (f.primitive < 0) {
      if (++depth_ > 64) return fail(path, "types nest deeper than 64");
      const bool ok = message(f.nested, v, path);
      --depth_;
      return ok;
    }
    switch (f.scalar.kind) {
      case Scalar::Kind::Bool:
        if (v != nullptr && !v->is_boolean()) return fail(path, "must be true or false");
        out_.boolean(v != nullptr && v->get<bool>());
        return true;
      case Scalar::Kind::String: {
        if (v == nullptr) {
          out_.string("");
          return true;
        }
        if (!v->is_string()) return fail(path, "must be a string");
        const std::string& s = v->get_ref<const std::string&>();
        if (f.string_capacity != 0 && s.size() > f.string_capacity)
          return fail(path, "must be at most " + std::to_string(f.string_capacity) + " characters, has " +
                                std::to_string(s.size()));
        out_.string(s);
        return true;
      }
      case Scalar::Kind::Float:
        return real(f.scalar.size, v, path);
      case Scalar::Kind::Int:
      case Scalar::Kind::UInt:
      case Scalar::Kind::Length:
        return integer(f.scalar, v, path);
    }
    return fail(path, "unsupported type");
  }

  bool real(std::uint8_t size, const JsonValue* v, const std::string& path) {
    double d = 0.0;
    if (v != nullptr) {
      if (v->is_null()) {
        d = std::numeric_limits<double>::quiet_NaN();  // to_json's null: not finite
      } else if (v->is_number()) {
        // A bare "-0" is nlohmann's integer 0 and comes in as +0.0; to_json writes -0.0 as "-0.0".
        d = v->get<double>();
      } else {
        return fail(path, "must be a number (or null for NaN)");
      }
    }
    if (size == 4) {
      // What rounds to float32's largest finite value is in range (to_json writes that value as
      // 3.4028235e+38, above it as a double); from half an ulp past it, it would round to infinity.
      const double limit = std::ldexp(1.0, 128) - std::ldexp(1.0, 103);
      if (std::isfinite(d) && std::fabs(d) >= limit) return fail(path, "must be within float32's range");
      out_.f32(static_cast<float>(d));
    } else {
      out_.f64(d);
    }
    return true;
  }

  bool integer(const PrimitiveType& p, const JsonValue* v, const std::string& path) {
    const bool is_signed = p.kind == Scalar::Kind::Int;
    const unsigned bits = 8u * p.size;
    // The range as what the JSON can hold: min and max of an int64 / uint64 view.
    const std::int64_t lo =
        is_signed ? (bits == 64 ? std::numeric_limits<std::int64_t>::min() : -(std::int64_t{1} << (bits - 1)))
                  : 0;
    const std::uint64_t hi =
        is_signed ? (bits == 64 ? static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max())
                                : (std::uint64_t{1} << (bits - 1)) - 1)
                  : (bits == 64 ? std::numeric_limits<std::uint64_t>::max() : (std::uint64_t{1} << bits) - 1);
    const auto range = [&] {
      return fail(path, "must be an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    };
    std::uint64_t u = 0;  // the value's bits (two's complement for a negative one)
    if (v != nullptr) {
      if (v->is_number_unsigned()) {
        const std::uint64_t x = v->get<std::uint64_t>();
        if (x > hi) return range();
        u = x;
      } else if (v->is_number_integer()) {
        const std::int64_t x = v->get<std::int64_t>();
        if (x < lo || (x >= 0 && static_cast<std::uint64_t>(x) > hi)) return range();
        u = static_cast<std::uint64_t>(x);
      } else if (v->is_number_float()) {
        // An integral value written as a float (2.0, 1e3): a JavaScript client cannot tell them apart.
        const double d = v->get<double>();
        if (!std::isfinite(d) || d != std::floor(d) || d < static_cast<double>(lo) ||
            d >= 18446744073709551616.0 || (d >= 0 && static_cast<std::uint64_t>(d) > hi))
          return range();
        u = d < 0 ? static_cast<std::uint64_t>(static_cast<std::int64_t>(d)) : static_cast<std::uint64_t>(d);
      } else {
        return range();
      }
    }
    switch (p.size) {
      case 1:
        out_.u8(static_cast<std::uint8_t>(u));
        break;
      case 2:
        out_.u16(static_cast<std::uint16_t>(u));
        break;
      case 4:
        out_.u32(static_cast<std::uint32_t>(u));
        break;
      default:
        out_.u64(u);
        break;
    }
    return true;
  }

  bool fail(const std::string& path, const std::string& why) {
    error = (path.empty() ? std::string("the message") : path) + ": " + why;
    return false;
  }

  const std::vector<MessageDecoder::Type>& types_;
  detail::CdrWriter& out_;
  int depth_ = 0;
};

}  // namespace

Status MessageDecoder::from_json(std::string_view json, Bytes& cdr) const {
  if (too_deep(json)) return Error{"JSON nests deeper than " + std::to_string(kMaxJsonDepth) + " levels"};
  JsonValue value;
  try {
    value = JsonValue::parse(json);
  } catch (const JsonValue::exception& e) {
    return Error{std::string("not JSON: ") + e.what()};
  }
  Bytes out;
  std::string error;
  {
    detail::CdrWriter w(out);  // finishes (pads) the message when it goes
    Writer writer(types_, w);
    std::string path;
    if (!writer.message(0, &value, path)) error = std::move(writer.error);
  }
  if (!error.empty()) return Error{std::move(error)};
  cdr = std::move(out);
  return Ok{};
}

}  // namespace rbsim::msgs
