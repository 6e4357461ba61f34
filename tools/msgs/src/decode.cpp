// Parsing ros2msg schemas and decoding CDR by them.
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <sstream>

#include "cdr.hpp"
#include "rbsim/cdr.hpp"
#include "rbsim/msgs.hpp"

namespace rbsim::msgs {

namespace {

struct Primitive {
  std::string_view name;
  std::uint8_t size;  // 0 = string
  Scalar::Kind kind;
};
constexpr Primitive kPrimitives[] = {
    {"bool", 1, Scalar::Kind::Bool},     {"byte", 1, Scalar::Kind::UInt},
    {"char", 1, Scalar::Kind::UInt},     {"int8", 1, Scalar::Kind::Int},
    {"uint8", 1, Scalar::Kind::UInt},    {"int16", 2, Scalar::Kind::Int},
    {"uint16", 2, Scalar::Kind::UInt},   {"int32", 4, Scalar::Kind::Int},
    {"uint32", 4, Scalar::Kind::UInt},   {"int64", 8, Scalar::Kind::Int},
    {"uint64", 8, Scalar::Kind::UInt},   {"float32", 4, Scalar::Kind::Float},
    {"float64", 8, Scalar::Kind::Float}, {"string", 0, Scalar::Kind::String},
};

int primitive_index(std::string_view t) {
  if (t.starts_with("string<=")) t = "string";
  for (std::size_t i = 0; i < std::size(kPrimitives); ++i) {
    if (kPrimitives[i].name == t) return static_cast<int>(i);
  }
  return -1;
}

// Walks one message through the CDR cursor; `Visit` is called with each scalar. Returns false on
// malformed data.
class Walker {
 public:
  Walker(const std::vector<MessageDecoder::Type>& types, std::span<const std::byte> cdr)
      : types_(types), cdr_(cdr), at_(cdr) {}
  // A walk of one value starting where `at` stands (inside a message whose header was checked).
  Walker(const std::vector<MessageDecoder::Type>& types, const CdrCursor& at)
      : types_(types), cdr_(), at_(at) {}
  std::string error;

  // The root type once, from the cursor, no header check: a value embedded in a larger message.
  template <class Visit>
  bool value(Visit&& visit) {
    return type(0, visit);
  }
  const CdrCursor& cursor() const { return at_; }

  template <class Visit>
  bool message(Visit&& visit) {
    if (cdr_.size() < CdrCursor::kHeader) return fail("shorter than the 4-byte encapsulation header");
    if (!CdrCursor::plain_header(cdr_)) {
      return fail("unsupported CDR encapsulation (only plain little-endian CDR, 00 01, is read)");
    }
    return type(0, visit);
  }

 private:
  template <class Visit>
  bool type(std::size_t t, Visit& visit) {
    if (++depth_ > 64) return fail("types nest deeper than 64");
    visit.begin_object();
    for (const MessageDecoder::Field& f : types_[t].fields) {
      visit.enter(f);
      std::uint64_t count = 1;
      if (f.array == MessageDecoder::Field::Array::Sequence) {
        std::uint32_t n = 0;
        if (!read(4, &n)) return false;
        if (n > at_.remaining()) return fail("sequence length " + std::to_string(n) + " exceeds the data");
        Scalar len;
        len.kind = Scalar::Kind::Length;
        len.u = n;
        visit.scalar(len, true);
        count = n;
      } else if (f.array == MessageDecoder::Field::Array::Fixed) {
        count = f.fixed_size;
      }
      for (std::uint64_t k = 0; k < count; ++k) {
        if (f.array != MessageDecoder::Field::Array::None) visit.index(k);
        if (f.primitive >= 0 ? !primitive(kPrimitives[f.primitive], visit) : !type(f.nested, visit))
          return false;
        if constexpr (requires { visit.done(); }) {
          if (visit.done()) return true;  // the visitor has what it wanted: stop walking
        }
        if (f.array != MessageDecoder::Field::Array::None) visit.unindex();
      }
      visit.leave(f);
    }
    visit.end_object();
    --depth_;
    return true;
  }
  template <class Visit>
  bool primitive(const Primitive& p, Visit& visit) {
    Scalar s;
    s.kind = p.kind;
    if (p.size == 0) {
      std::uint32_t n = 0;
      if (!read(4, &n)) return false;
      if (n == 0 || n > at_.remaining()) return fail("string length " + std::to_string(n) + " invalid");
      s.s = std::string_view(reinterpret_cast<const char*>(at_.here()), n - 1);
      at_.advance(n);
    } else {
      std::byte raw[8] = {};
      if (!read(p.size, raw)) return false;
      if constexpr (requires { visit.bits(raw, p.size); }) {
        visit.bits(raw, p.size);  // the value's bytes as they were (a copy, bit for bit)
        return true;
      }
      s = load_scalar(raw, p.size, p.kind);
    }
    visit.scalar(s, false);
    return true;
  }
  bool read(std::size_t size, void* out) {
    if (!at_.read(size, out)) return fail("truncated at byte " + std::to_string(at_.pos()));
    return true;
  }
  bool fail(std::string why) {
    error = std::move(why);
    return false;
  }
  const std::vector<MessageDecoder::Type>& types_;
  std::span<const std::byte> cdr_;
  CdrCursor at_;  // after the header, used once message() has checked it
  int depth_ = 0;
};

struct Collect {
  std::vector<Scalar>* out;
  void begin_object() {}
  void end_object() {}
  void enter(const MessageDecoder::Field&) {}
  void leave(const MessageDecoder::Field&) {}
  void index(std::uint64_t) {}
  void unindex() {}
  void scalar(const Scalar& s, bool) { out->push_back(s); }
};

// Writes each value as it is read, aligned where it lands in the writer's message (a value moved
// to another offset, e.g. a request embedded in its service's _Event, keeps CDR's alignment rule
// there: an 8-byte field after an odd-sized one gets the padding of its new place, not its old).
struct Copy {
  detail::CdrWriter* to;
  void begin_object() {}
  void end_object() {}
  void enter(const MessageDecoder::Field&) {}
  void leave(const MessageDecoder::Field&) {}
  void index(std::uint64_t) {}
  void unindex() {}
  // Sequence lengths and strings (every other primitive comes through bits()).
  void scalar(const Scalar& s, bool is_length) {
    if (is_length) return to->sequence_length(static_cast<std::size_t>(s.u));
    to->string(s.s);
  }
  // A primitive of `size` bytes, copied bit for bit (a NaN's payload, a float's -0 kept).
  void bits(const std::byte* raw, std::uint8_t size) {
    switch (size) {
      case 1:
        return to->u8(CdrCursor::load<std::uint8_t>(raw));
      case 2:
        return to->u16(CdrCursor::load<std::uint16_t>(raw));
      case 4:
        return to->u32(CdrCursor::load<std::uint32_t>(raw));
      default:
        return to->u64(CdrCursor::load<std::uint64_t>(raw));
    }
  }
};

// Builds the path of scalar number `target` while walking; stops the walk there. The path is
// kept as a stack of field names and indices and spelled out only for the target.
struct PathOf {
  struct Part {
    const std::string* name = nullptr;  // null: an index
    std::uint64_t index = 0;
  };
  std::size_t target;
  std::size_t seen = 0;
  std::vector<Part> parts;
  std::string found;
  bool done() const { return seen > target; }
  void begin_object() {}
  void end_object() {}
  void enter(const MessageDecoder::Field& f) { parts.push_back({&f.name, 0}); }
  void leave(const MessageDecoder::Field&) { parts.pop_back(); }
  void index(std::uint64_t k) { parts.push_back({nullptr, k}); }
  void unindex() { parts.pop_back(); }
  void scalar(const Scalar&, bool is_length) {
    if (seen++ != target) return;
    for (std::size_t i = 0; i < parts.size(); ++i) {
      if (parts[i].name == nullptr) {
        found += "[" + std::to_string(parts[i].index) + "]";
      } else {
        if (i > 0) found += '.';
        found += *parts[i].name;
      }
    }
    if (is_length) found += ".length";
  }
};

// Writes the message as JSON while walking: objects for messages, arrays for arrays.
struct Json {
  explicit Json(std::string* o) : out(o) {}
  std::string* out;
  std::vector<bool> first;  // per open object: no member written yet
  bool float32 = false;     // the field being written is float32
  void begin_object() {
    *out += '{';
    first.push_back(true);
  }
  void end_object() {
    *out += '}';
    first.pop_back();
  }
  void enter(const MessageDecoder::Field& f) {
    if (!first.back()) *out += ',';
    first.back() = false;
    append_json_string(*out, f.name);
    *out += ':';
    if (f.array != MessageDecoder::Field::Array::None) *out += '[';
    float32 = f.primitive >= 0 && kPrimitives[f.primitive].kind == Scalar::Kind::Float &&
              kPrimitives[f.primitive].size == 4;
  }
  void leave(const MessageDecoder::Field& f) {
    if (f.array != MessageDecoder::Field::Array::None) *out += ']';
  }
  void index(std::uint64_t k) {
    if (k > 0) *out += ',';
  }
  void unindex() {}
  void scalar(const Scalar& s, bool is_length) {
    if (is_length) return;  // the array's own length
    char buf[40];
    switch (s.kind) {
      case Scalar::Kind::Bool:
        *out += s.i ? "true" : "false";
        return;
      case Scalar::Kind::Int:
        *out += std::to_string(s.i);
        return;
      case Scalar::Kind::UInt:
      case Scalar::Kind::Length:
        *out += std::to_string(s.u);
        return;
      case Scalar::Kind::String:
        append_json_string(*out, s.s);
        return;
      case Scalar::Kind::Float: {
        if (!std::isfinite(s.f)) {
          *out += "null";  // JSON has no NaN or infinity
          return;
        }
        if (s.f == 0.0 && std::signbit(s.f)) {
          // to_chars writes "-0", which JSON readers may take for the integer 0 (nlohmann does):
          // the fraction keeps it a float, so -0.0 reads back as itself.
          *out += "-0.0";
          return;
        }
        const auto r = float32 ? std::to_chars(buf, buf + sizeof buf, static_cast<float>(s.f))
                               : std::to_chars(buf, buf + sizeof buf, s.f);
        out->append(buf, r.ptr);
        return;
      }
    }
  }
};

}  // namespace

void append_json_string(std::string& out, std::string_view text) {
  out += '"';
  for (const char c : text) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\r':
        out += "\\r";
        break;
      case '\t':
        out += "\\t";
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", static_cast<unsigned>(static_cast<unsigned char>(c)));
          out += buf;
        } else {
          out += c;
        }
    }
  }
  out += '"';
}

std::string Scalar::to_string() const {
  switch (kind) {
    case Kind::Bool:
      return i ? "true" : "false";
    case Kind::Int:
      return std::to_string(i);
    case Kind::UInt:
    case Kind::Length:
      return std::to_string(u);
    case Kind::String:
      return "\"" + std::string(s) + "\"";
    case Kind::Float: {
      char buf[32];
      std::snprintf(buf, sizeof buf, "%.17g", f);
      return buf;
    }
  }
  return "?";
}

std::string canonical_type(std::string_view type, std::string_view package) {
  if (type == "Header") return "std_msgs/msg/Header";
  const auto slash = type.find('/');
  if (slash == std::string_view::npos) return std::string(package) + "/msg/" + std::string(type);
  if (type.find('/', slash + 1) != std::string_view::npos) return std::string(type);
  return std::string(type.substr(0, slash)) + "/msg/" + std::string(type.substr(slash + 1));
}

std::map<std::string, std::string> schema_sections(std::string_view root, std::string_view schema) {
  std::map<std::string, std::string> sections;
  std::string current = canonical_type(root, ""), body;
  std::istringstream lines{std::string(schema)};
  std::string line;
  while (std::getline(lines, line)) {
    if (line.size() >= 3 && line.find_first_not_of('=') == std::string::npos) {
      sections[current] = std::move(body);
      body.clear();
      current.clear();
      continue;
    }
    if (current.empty() && line.starts_with("MSG: ")) {
      current = canonical_type(line.substr(5), "");
      continue;
    }
    body += line + "\n";
  }
  if (!current.empty()) sections[current] = std::move(body);
  return sections;
}

std::optional<PrimitiveType> primitive_type(std::string_view type) {
  const int i = primitive_index(type);
  if (i < 0) return std::nullopt;
  return PrimitiveType{kPrimitives[i].kind, kPrimitives[i].size};
}

namespace {
// A decimal array size or bound: digits only, at most UINT32_MAX.
std::optional<std::uint32_t> parse_bound(std::string_view digits) {
  std::uint32_t n = 0;
  const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), n);
  if (digits.empty() || ec != std::errc() || end != digits.data() + digits.size()) return std::nullopt;
  return n;
}
}  // namespace

Result<std::vector<MsgField>> parse_msg_fields(std::string_view type, std::string_view text) {
  const std::string name(type);
  const std::string package = name.substr(0, name.find('/'));
  std::vector<MsgField> fields;
  std::istringstream def{std::string(text)};
  std::string line;
  while (std::getline(def, line)) {
    if (const auto hash = line.find('#'); hash != std::string::npos) line.resize(hash);
    std::istringstream words(line);
    std::string field_type, field;
    if (!(words >> field_type)) continue;
    if (!(words >> field)) return Error{name + ": field without a name: " + field_type};
    if (field.find('=') != std::string::npos) continue;  // constant "int32 X=3"
    std::string rest;
    if (words >> rest && rest.starts_with('=')) continue;  // constant "int32 X = 3"
    MsgField f;
    f.name = field;
    if (!rest.empty()) {  // a default value: the rest of the line, trimmed ("[1, 2]" has spaces)
      std::string tail;
      std::getline(words, tail);
      f.default_text = rest + tail;
      while (!f.default_text.empty() && std::isspace(static_cast<unsigned char>(f.default_text.back())))
        f.default_text.pop_back();
    }
    if (const auto bracket = field_type.find('['); bracket != std::string::npos) {
      if (field_type.back() != ']') return Error{name + ": bad array type in " + line};
      const std::string inside = field_type.substr(bracket + 1, field_type.size() - bracket - 2);
      field_type.resize(bracket);
      if (inside.empty()) {
        f.array = MsgField::Array::Sequence;
      } else if (inside.starts_with("<=")) {
        f.array = MsgField::Array::Sequence;
        const auto n = parse_bound(std::string_view(inside).substr(2));
        if (!n) return Error{name + ": bad sequence bound in " + line};
        f.sequence_bound = *n;
      } else {
        const auto n = parse_bound(inside);
        if (!n) return Error{name + ": bad array size in " + line};
        f.array = MsgField::Array::Fixed;
        f.fixed_size = *n;
      }
    }
    if (field_type == "wstring" || field_type.starts_with("wstring<="))
      return Error{name + ": wstring fields are not supported"};
    if (field_type.starts_with("string<=")) {
      const auto n = parse_bound(std::string_view(field_type).substr(8));
      if (!n || *n == 0) return Error{name + ": bad string bound in " + line};
      f.string_capacity = *n;
    }
    f.primitive = primitive_type(field_type);
    f.type = f.primitive ? field_type : canonical_type(field_type, package);
    fields.push_back(std::move(f));
  }
  // rosidl gives a message without fields one uint8 member, so every element has a size.
  if (fields.empty()) {
    MsgField placeholder;
    placeholder.name = "structure_needs_at_least_one_member";
    placeholder.type = "uint8";
    placeholder.primitive = primitive_type("uint8");
    fields.push_back(std::move(placeholder));
  }
  return fields;
}

Result<MessageDecoder> MessageDecoder::create(std::string_view root, std::string_view schema) {
  const std::string root_name = canonical_type(root, "");
  const std::map<std::string, std::string> sections = schema_sections(root_name, schema);

  MessageDecoder d;
  std::map<std::string, std::size_t> index;
  index[root_name] = 0;
  d.types_.push_back(Type{root_name, {}});
  for (std::size_t t = 0; t < d.types_.size(); ++t) {
    const std::string name = d.types_[t].name;
    const auto it = sections.find(name);
    if (it == sections.end()) return Error{"schema has no definition for " + name};
    auto parsed = parse_msg_fields(name, it->second);
    if (!parsed) return parsed.error();
    for (MsgField& m : parsed.value()) {
      Field f;
      f.name = std::move(m.name);
      f.array = m.array;
      f.fixed_size = m.fixed_size;
      f.sequence_bound = m.sequence_bound;
      f.string_capacity = m.string_capacity;
      if (m.primitive) f.scalar = *m.primitive;
      f.primitive = m.primitive ? primitive_index(m.type) : -1;
      if (!m.primitive) {
        auto [pos, fresh] = index.try_emplace(m.type, d.types_.size());
        if (fresh) d.types_.push_back(Type{m.type, {}});
        f.nested = pos->second;
      }
      d.types_[t].fields.push_back(std::move(f));
    }
  }
  return d;
}

Status MessageDecoder::decode(std::span<const std::byte> cdr, std::vector<Scalar>& out) const {
  out.clear();
  Walker w(types_, cdr);
  Collect c{&out};
  if (!w.message(c)) return Error{"CDR: " + w.error};
  return Ok{};
}

Status MessageDecoder::to_json(std::span<const std::byte> cdr, std::string& out) const {
  const std::size_t start = out.size();
  Walker w(types_, cdr);
  Json j(&out);
  if (!w.message(j)) {
    out.resize(start);
    return Error{"CDR: " + w.error};
  }
  return Ok{};
}

Status MessageDecoder::copy(CdrCursor& from, detail::CdrWriter& to) const {
  Walker w(types_, from);
  Copy c{&to};
  if (!w.value(c)) return Error{"CDR: " + types_[0].name + ": " + w.error};
  from = w.cursor();
  return Ok{};
}

std::string MessageDecoder::path(std::span<const std::byte> cdr, std::size_t index) const {
  Walker w(types_, cdr);
  PathOf p{index, 0, {}, {}};
  w.message(p);
  return p.found.empty() ? "[" + std::to_string(index) + "]" : p.found;
}

}  // namespace rbsim::msgs
