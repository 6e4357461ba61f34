// REP 2011 type descriptions and hashes (RIHS01) from the shipped .msg/.srv/.action definitions. The
// description and its JSON follow rosidl_generator_type_description (Jazzy): field type ids of
// type_description_interfaces/msg/FieldType, capacities, string capacities, nested type names; the
// referenced types sorted by name; json.dumps with separators (", ", ": ") and no default values.
#include "rbsim/type_hash.hpp"

#include <openssl/evp.h>

#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <deque>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <vector>

#include "definitions.hpp"
#include "list_items.hpp"
#include "rbsim/msgs.hpp"

namespace rbsim::msgs {

namespace {

using detail::definition_part;

constexpr std::string_view kRequest = kServiceRequestSuffix;
constexpr std::string_view kResponse = kServiceResponseSuffix;
constexpr std::string_view kEvent = kServiceEventSuffix;
constexpr std::string_view kEventInfo = "service_msgs/msg/ServiceEventInfo";
// What rosidl_parser's Action makes of pkg/action/Name (definition.py: ACTION_*_SUFFIX).
constexpr std::string_view kGoal = "_Goal";
constexpr std::string_view kResult = "_Result";
constexpr std::string_view kFeedback = "_Feedback";
constexpr std::string_view kSendGoal = "_SendGoal";
constexpr std::string_view kGetResult = "_GetResult";
constexpr std::string_view kFeedbackMessage = "_FeedbackMessage";
constexpr std::string_view kUuid = "unique_identifier_msgs/msg/UUID";
constexpr std::string_view kTime = "builtin_interfaces/msg/Time";
// A hostile or broken definition source cannot make a description grow without end.
constexpr std::size_t kMaxTypes = 4096;

// type_description_interfaces/msg/FieldType: the value type ids, and the offsets rosidl adds for
// a fixed array, a bounded and an unbounded sequence of them.
constexpr std::uint8_t kNestedType = 1;
constexpr std::uint8_t kInt8 = 2;
constexpr std::uint8_t kBool = 15;
constexpr std::uint8_t kBoundedString = 21;
constexpr std::uint8_t kArrayOffset = 48;
constexpr std::uint8_t kBoundedSequenceOffset = 96;
constexpr std::uint8_t kUnboundedSequenceOffset = 144;

// .msg primitive -> FieldType id. rosidl maps .msg to IDL first: char becomes uint8 (not IDL char)
// and byte becomes octet (FIELD_TYPE_BYTE), so char hashes as uint8.
std::optional<std::uint8_t> primitive_type_id(std::string_view t) {
  struct Entry {
    std::string_view msg;
    std::uint8_t id;
  };
  static constexpr Entry kIds[] = {
      {"int8", 2},     {"uint8", 3},  {"char", 3},  {"int16", 4},   {"uint16", 5},
      {"int32", 6},    {"uint32", 7}, {"int64", 8}, {"uint64", 9},  {"float32", 10},
      {"float64", 11}, {"bool", 15},  {"byte", 16}, {"string", 17},
  };
  if (t.starts_with("string<=")) return kBoundedString;
  for (const Entry& e : kIds) {
    if (e.msg == t) return e.id;
  }
  return std::nullopt;
}

// ROS names are identifiers: [A-Za-z][A-Za-z0-9_]*. Checking them keeps the JSON what rosidl would
// write (no escapes needed) and rejects garbage with a clear message.
bool is_identifier(std::string_view s) {
  if (s.empty() || !((s[0] >= 'A' && s[0] <= 'Z') || (s[0] >= 'a' && s[0] <= 'z'))) return false;
  for (const char c : s) {
    if (!((c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_'))
      return false;
  }
  return true;
}

struct TypeName {
  std::string_view package, kind, name;
};
// "pkg/msg/Name", "pkg/srv/Name" or "pkg/action/Name", each part an identifier.
std::optional<TypeName> split_type(std::string_view full) {
  const auto a = full.find('/');
  if (a == std::string_view::npos) return std::nullopt;
  const auto b = full.find('/', a + 1);
  if (b == std::string_view::npos) return std::nullopt;
  TypeName n{full.substr(0, a), full.substr(a + 1, b - a - 1), full.substr(b + 1)};
  if (!is_identifier(n.package) || (n.kind != "msg" && n.kind != "srv" && n.kind != "action") ||
      !is_identifier(n.name)) {
    return std::nullopt;
  }
  return n;
}

Field nested_field(std::string name, std::string type, std::uint8_t id, std::uint64_t capacity) {
  return Field{std::move(name), FieldType{id, capacity, 0, std::move(type)}, ""};
}
// A field of a type rosidl derives (an action's service messages): a primitive, no default.
Field primitive_field(std::string name, std::uint8_t id) {
  return Field{std::move(name), FieldType{id, 0, 0, ""}, ""};
}

// ---------------------------------------------------------------------------------------------
// Field.default_value as rosidl fills it: rosidl_adapter parses the .msg default into a Python
// value, writes it into the IDL as an @default annotation, and rosidl_generator_type_description
// stores str() of what rosidl_parser reads back. So a float is Python's repr (0 -> "0.0", 1e-05),
// a bool "True"/"False", an integer in decimal, a string its text without the quotes, an array the
// repr of a tuple ("(0.0, 1.0)", "(1,)"). REP 2011 leaves defaults out of the hash.

// Python's repr of a float: the shortest round trip, in fixed notation for exponents in [-4, 16)
// (with ".0" when integral), else d.ddde+XX, which std::to_chars' scientific form already is.
std::string python_float_repr(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buf[64];
  const auto sci = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::scientific);
  const std::string_view s(buf, static_cast<std::size_t>(sci.ptr - buf));
  const int exponent = std::atoi(std::string(s.substr(s.find('e') + 1)).c_str());
  if (exponent < -4 || exponent >= 16) return std::string(s);
  const auto fixed = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::fixed);
  std::string out(buf, static_cast<std::size_t>(fixed.ptr - buf));
  if (out.find('.') == std::string::npos) out += ".0";
  return out;
}

// A whole number as Python's int(text) or int(text, 0) reads it (0x, 0o, 0b prefixes), in decimal
// (uint64's whole range, and its negatives).
std::optional<std::string> python_int(std::string_view text) {
  bool negative = false;
  if (!text.empty() && (text[0] == '-' || text[0] == '+')) {
    negative = text[0] == '-';
    text.remove_prefix(1);
  }
  int base = 10;
  if (text.size() > 2 && text[0] == '0') {
    const char p = static_cast<char>(std::tolower(static_cast<unsigned char>(text[1])));
    base = p == 'x' ? 16 : p == 'o' ? 8 : p == 'b' ? 2 : 10;
    if (base != 10) text.remove_prefix(2);
  }
  unsigned long long n = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), n, base);
  if (text.empty() || ec != std::errc() || end != text.data() + text.size()) return std::nullopt;
  return (negative && n != 0 ? "-" : "") + std::to_string(n);
}

// One scalar default of a primitive type (`quoted`: a string inside an array, as repr quotes it).
Result<std::string> scalar_default(std::string_view type, std::string_view text, bool quoted) {
  const auto bad = [&] {
    return Error{"bad default value \"" + std::string(text) + "\" for " + std::string(type)};
  };
  if (type == "bool") {
    std::string lower(text);
    for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (lower == "true" || lower == "1") return std::string("True");
    if (lower == "false" || lower == "0") return std::string("False");
    return bad();
  }
  if (type == "float32" || type == "float64") {
    double v = 0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
    if (text.empty() || ec != std::errc() || end != text.data() + text.size()) return bad();
    return python_float_repr(v);
  }
  if (type == "string" || type.starts_with("string<=")) {
    // rosidl_adapter drops one pair of outer quotes.
    if (text.size() >= 2 && (text[0] == '"' || text[0] == '\'') && text.back() == text[0])
      text = text.substr(1, text.size() - 2);
    return quoted ? "'" + std::string(text) + "'" : std::string(text);
  }
  auto n = python_int(text);
  if (!n) return bad();
  return std::move(*n);
}

Result<std::string> rosidl_default_value(const MsgField& f) {
  if (f.default_text.empty()) return std::string();
  if (!f.primitive) return Error{"a nested type cannot have a default value"};
  if (f.array == MsgField::Array::None) return scalar_default(f.type, f.default_text, false);
  std::string_view list = f.default_text;
  if (list.size() < 2 || list.front() != '[' || list.back() != ']')
    return Error{"an array default must be written [a, b, ...]: " + f.default_text};
  std::string out = "(";
  std::size_t count = 0;
  for (const std::string_view item : detail::list_items(list.substr(1, list.size() - 2))) {
    auto value = scalar_default(f.type, item, true);
    if (!value) return value.error();
    out += (count++ > 0 ? ", " : "") + value.value();
  }
  return out + (count == 1 ? ",)" : ")");
}

// TypeSource.raw_file_contents as rosidl_generator_c embeds a definition file: its lines
// (Python's splitlines: \n, \r\n or \r) joined by \n, so the final newline is dropped.
std::string rosidl_source_text(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] == '\r') {
      if (i + 1 < text.size() && text[i + 1] == '\n') ++i;
      out += '\n';
    } else {
      out += text[i];
    }
  }
  if (!out.empty() && out.back() == '\n') out.pop_back();
  return out;
}

Result<Field> describe_field(std::string_view owner, const MsgField& f) {
  if (!is_identifier(f.name)) return Error{std::string(owner) + ": bad field name \"" + f.name + "\""};
  Field d;
  d.name = f.name;
  FieldType& t = d.type;
  if (f.primitive) {
    const auto id = primitive_type_id(f.type);
    if (!id) return Error{std::string(owner) + ": field " + f.name + " has unsupported type " + f.type};
    t.type_id = *id;
    t.string_capacity = f.string_capacity;
  } else {
    if (!split_type(f.type))
      return Error{std::string(owner) + ": field " + f.name + " has bad type " + f.type};
    t.type_id = kNestedType;
    t.nested_type_name = f.type;
  }
  switch (f.array) {
    case MsgField::Array::None:
      break;
    case MsgField::Array::Fixed:
      t.type_id = static_cast<std::uint8_t>(t.type_id + kArrayOffset);
      t.capacity = f.fixed_size;
      break;
    case MsgField::Array::Sequence:
      t.type_id = static_cast<std::uint8_t>(
          t.type_id + (f.sequence_bound > 0 ? kBoundedSequenceOffset : kUnboundedSequenceOffset));
      t.capacity = f.sequence_bound;
      break;
  }
  auto value = rosidl_default_value(f);
  if (!value) return Error{std::string(owner) + ": field " + f.name + ": " + value.error().message};
  d.default_value = std::move(value.value());
  return d;
}

Result<IndividualTypeDescription> describe_msg_text(std::string_view type, std::string_view text) {
  auto parsed = parse_msg_fields(type, text);
  if (!parsed) return parsed.error();
  IndividualTypeDescription d{std::string(type), {}};
  for (const MsgField& f : parsed.value()) {
    auto field = describe_field(type, f);
    if (!field) return field.error();
    d.fields.push_back(std::move(field.value()));
  }
  return d;
}

// `name` without `suffix`, when it ends with it and something comes before.
std::optional<std::string_view> strip_suffix(std::string_view name, std::string_view suffix) {
  if (!name.ends_with(suffix) || name.size() == suffix.size()) return std::nullopt;
  return name.substr(0, name.size() - suffix.size());
}

// A service type: "pkg/srv/Name" with a .srv text, or an action's "pkg/action/Name_SendGoal" or
// "pkg/action/Name_GetResult" (rosidl_parser's Action.send_goal_service and get_result_service).
// Returns the action ("pkg/action/Name") for the latter, the service itself for the former.
std::optional<std::string> service_origin(const TypeName& n, const DefinitionSource& source) {
  const std::string full = std::string(n.package) + "/" + std::string(n.kind) + "/" + std::string(n.name);
  if (n.kind == "srv") return source(full) ? std::optional(full) : std::nullopt;
  if (n.kind != "action") return std::nullopt;
  for (const std::string_view suffix : {kSendGoal, kGetResult}) {
    const auto action = strip_suffix(n.name, suffix);
    if (!action) continue;
    const std::string origin = std::string(n.package) + "/action/" + std::string(*action);
    if (source(origin)) return origin;
  }
  return std::nullopt;
}

// The request or response of an action's generated service, as rosidl_parser's Action builds them:
// _SendGoal_Request {UUID goal_id, _Goal goal}, _SendGoal_Response {bool accepted, Time stamp},
// _GetResult_Request {UUID goal_id}, _GetResult_Response {int8 status, _Result result}.
IndividualTypeDescription action_service_message(const std::string& type, const std::string& service,
                                                 const std::string& action, bool request) {
  const std::string uuid(kUuid);
  if (service.ends_with(kSendGoal)) {
    if (request) {
      return {type,
              {nested_field("goal_id", uuid, kNestedType, 0),
               nested_field("goal", action + std::string(kGoal), kNestedType, 0)}};
    }
    return {type,
            {primitive_field("accepted", kBool), nested_field("stamp", std::string(kTime), kNestedType, 0)}};
  }
  if (request) return {type, {nested_field("goal_id", uuid, kNestedType, 0)}};
  return {type,
          {primitive_field("status", kInt8),
           nested_field("result", action + std::string(kResult), kNestedType, 0)}};
}

// A service's _Request, _Response or _Event message (`suffix`); `service` is a service_origin().
Result<IndividualTypeDescription> describe_service_message(std::string_view type, const std::string& service,
                                                           const std::string& origin, std::string_view suffix,
                                                           const DefinitionSource& source) {
  if (suffix == kEvent) {
    // rosidl_parser's Service.event_message: info, then the request and the response each as a
    // sequence of at most one.
    return IndividualTypeDescription{
        std::string(type),
        {nested_field("info", std::string(kEventInfo), kNestedType, 0),
         nested_field("request", service + std::string(kRequest), kNestedType + kBoundedSequenceOffset, 1),
         nested_field("response", service + std::string(kResponse), kNestedType + kBoundedSequenceOffset,
                      1)}};
  }
  if (origin != service)
    return action_service_message(std::string(type), service, origin, suffix == kRequest);
  const auto text = source(service);
  if (!text) return Error{"no definition for " + service + " (for " + std::string(type) + ")"};
  auto part = definition_part(service, *text, suffix == kRequest ? 0 : 1, 2);
  if (!part) return part.error();
  return describe_msg_text(type, part.value());
}

// A type rosidl derives from an action (`action` has a definition): the action itself, its goal,
// result and feedback (the three parts of the .action text) or the feedback message.
Result<IndividualTypeDescription> describe_action_type(std::string_view type, const std::string& action,
                                                       std::string_view suffix, std::string_view text) {
  if (suffix.empty()) {
    // rosidl_generator_type_description's add_action: the six types rosidl makes of it.
    return IndividualTypeDescription{
        action,
        {nested_field("goal", action + std::string(kGoal), kNestedType, 0),
         nested_field("result", action + std::string(kResult), kNestedType, 0),
         nested_field("feedback", action + std::string(kFeedback), kNestedType, 0),
         nested_field("send_goal_service", action + std::string(kSendGoal), kNestedType, 0),
         nested_field("get_result_service", action + std::string(kGetResult), kNestedType, 0),
         nested_field("feedback_message", action + std::string(kFeedbackMessage), kNestedType, 0)}};
  }
  if (suffix == kFeedbackMessage) {
    return IndividualTypeDescription{
        std::string(type),
        {nested_field("goal_id", std::string(kUuid), kNestedType, 0),
         nested_field("feedback", action + std::string(kFeedback), kNestedType, 0)}};
  }
  const int part = suffix == kGoal ? 0 : suffix == kResult ? 1 : 2;
  auto part_text = definition_part(action, text, part, 3);
  if (!part_text) return part_text.error();
  return describe_msg_text(type, part_text.value());
}

// The service (`type` is a service_origin()) as rosidl_generator_type_description's add_srv
// describes it: its three messages.
IndividualTypeDescription service_description(const std::string& service) {
  return IndividualTypeDescription{
      service,
      {nested_field("request_message", service + std::string(kRequest), kNestedType, 0),
       nested_field("response_message", service + std::string(kResponse), kNestedType, 0),
       nested_field("event_message", service + std::string(kEvent), kNestedType, 0)}};
}

// The description of one type, without the types it refers to.
Result<IndividualTypeDescription> describe_type(std::string_view type, const DefinitionSource& source) {
  const auto name = split_type(type);
  if (!name)
    return Error{"\"" + std::string(type) +
                 "\" is not an interface type name (pkg/msg/Name, pkg/srv/Name or pkg/action/Name)"};
  if (name->kind == "msg") {
    const auto text = source(type);
    if (!text) return Error{"no definition for " + std::string(type)};
    return describe_msg_text(type, *text);
  }
  if (service_origin(*name, source)) return service_description(std::string(type));
  const std::string prefix = std::string(name->package) + "/" + std::string(name->kind) + "/";
  for (const std::string_view suffix : {kRequest, kResponse, kEvent}) {
    const auto base = strip_suffix(name->name, suffix);
    if (!base) continue;
    const std::string service = prefix + std::string(*base);
    const auto service_name = split_type(service);
    const auto origin = service_name ? service_origin(*service_name, source) : std::nullopt;
    if (!origin) {
      if (name->kind == "action") continue;
      return Error{"no definition for " + service + " (for " + std::string(type) + ")"};
    }
    return describe_service_message(type, service, *origin, suffix, source);
  }
  if (name->kind == "action") {
    for (const std::string_view suffix : {std::string_view(), kGoal, kResult, kFeedback, kFeedbackMessage}) {
      const auto base = suffix.empty() ? std::optional(name->name) : strip_suffix(name->name, suffix);
      if (!base) continue;
      const std::string action = prefix + std::string(*base);
      if (const auto text = source(action)) return describe_action_type(type, action, suffix, *text);
    }
  }
  return Error{"no definition for " + std::string(type)};
}

void append_type(std::string& out, const IndividualTypeDescription& d) {
  out += "{\"type_name\": ";
  append_json_string(out, d.type_name);
  out += ", \"fields\": [";
  for (std::size_t i = 0; i < d.fields.size(); ++i) {
    const Field& f = d.fields[i];
    out += i == 0 ? "{\"name\": " : ", {\"name\": ";
    append_json_string(out, f.name);
    out += ", \"type\": {\"type_id\": " + std::to_string(f.type.type_id);
    out += ", \"capacity\": " + std::to_string(f.type.capacity);
    out += ", \"string_capacity\": " + std::to_string(f.type.string_capacity);
    out += ", \"nested_type_name\": ";
    append_json_string(out, f.type.nested_type_name);
    out += "}}";
  }
  out += "]}";
}

// Lower-case hex SHA-256; nullopt if libcrypto refuses (no SHA-256 provider loaded).
std::optional<std::string> sha256_hex(std::string_view data) {
  std::array<unsigned char, EVP_MAX_MD_SIZE> digest{};
  unsigned int size = 0;
  if (EVP_Digest(data.data(), data.size(), digest.data(), &size, EVP_sha256(), nullptr) != 1 || size != 32) {
    return std::nullopt;
  }
  static constexpr char kHex[] = "0123456789abcdef";
  std::string hex;
  for (unsigned int i = 0; i < size; ++i) {
    hex += kHex[digest[i] >> 4];
    hex += kHex[digest[i] & 0xf];
  }
  return hex;
}

}  // namespace

std::optional<std::string_view> shipped_definition(std::string_view type) {
  const std::string_view text = definition(type);
  if (text.empty()) return std::nullopt;
  return text;
}

Result<TypeDescription> type_description(std::string_view type, const DefinitionSource& source) {
  const std::string root_name = canonical_type(type, "");
  auto root = describe_type(root_name, source);
  if (!root) return root.error();
  // Every type the root refers to, directly or not (rosidl's extract_full_type_description),
  // sorted by name.
  std::map<std::string, IndividualTypeDescription> referenced;
  std::deque<std::pair<std::string, std::string>> pending;  // (type, referenced by)
  for (const Field& f : root.value().fields) {
    if (!f.type.nested_type_name.empty()) pending.emplace_back(f.type.nested_type_name, root_name);
  }
  while (!pending.empty()) {
    auto [name, by] = std::move(pending.front());
    pending.pop_front();
    if (referenced.contains(name)) continue;
    if (referenced.size() >= kMaxTypes) return Error{root_name + ": refers to more than 4096 types"};
    auto d = describe_type(name, source);
    if (!d) return Error{root_name + ": " + d.error().message + " (referenced by " + by + ")"};
    for (const Field& f : d.value().fields) {
      if (!f.type.nested_type_name.empty()) pending.emplace_back(f.type.nested_type_name, name);
    }
    referenced.emplace(name, std::move(d.value()));
  }
  TypeDescription out{std::move(root.value()), {}};
  for (auto& [name, d] : referenced) out.referenced_type_descriptions.push_back(std::move(d));
  return out;
}

Result<TypeDescription> type_description(std::string_view type) {
  return type_description(type, shipped_definition);
}

std::string type_description_json(const TypeDescription& description) {
  std::string out = "{\"type_description\": ";
  append_type(out, description.type_description);
  out += ", \"referenced_type_descriptions\": [";
  bool first = true;
  for (const IndividualTypeDescription& d : description.referenced_type_descriptions) {
    if (!first) out += ", ";
    first = false;
    append_type(out, d);
  }
  out += "]}";
  return out;
}

Result<std::string> type_description_json(std::string_view type, const DefinitionSource& source) {
  auto description = type_description(type, source);
  if (!description) return description.error();
  return type_description_json(description.value());
}

Result<std::string> type_hash(const TypeDescription& description) {
  const auto hex = sha256_hex(type_description_json(description));
  if (!hex) {
    return Error{description.type_description.type_name + ": SHA-256 failed (OpenSSL libcrypto)"};
  }
  return "RIHS01_" + *hex;
}

Result<std::string> type_hash(std::string_view type, const DefinitionSource& source) {
  auto description = type_description(type, source);
  if (!description) return description.error();
  return type_hash(description.value());
}

std::vector<TypeSource> type_sources(const TypeDescription& description, const DefinitionSource& source) {
  std::vector<TypeSource> out;
  const auto add = [&](const std::string& name) {
    const auto text = source(name);
    // A type with a definition of its own is a .msg, .srv or .action file (its kind is the
    // encoding); one rosidl derives from a service or an action has none.
    if (!text) {
      out.push_back(TypeSource{name, "implicit", ""});
      return;
    }
    out.push_back(TypeSource{name, split_type(name) ? std::string(split_type(name)->kind) : "msg",
                             rosidl_source_text(*text)});
  };
  add(description.type_description.type_name);
  for (const IndividualTypeDescription& d : description.referenced_type_descriptions) add(d.type_name);
  return out;
}

Result<std::string> type_hash(std::string_view type) {
  static std::mutex mutex;
  static std::map<std::string, std::string, std::less<>> cache;
  const std::lock_guard lock(mutex);
  if (const auto it = cache.find(type); it != cache.end()) return it->second;
  auto hash = type_hash(type, shipped_definition);
  if (!hash) return hash.error();
  cache.emplace(std::string(type), hash.value());
  return hash;
}

// A service rbsim carries: a shipped "pkg/srv/Name", or one of the two services of a shipped action
// ("pkg/action/Name_SendGoal", "..._GetResult").
bool carried_service(std::string_view service) {
  const auto name = split_type(service);
  if (!name) return false;
  if (name->kind == "srv") return shipped_definition(service).has_value();
  if (name->kind != "action") return false;
  for (const std::string_view part : {std::string_view("_SendGoal"), std::string_view("_GetResult")}) {
    if (service.ends_with(part))
      return shipped_definition(service.substr(0, service.size() - part.size())).has_value();
  }
  return false;
}

Result<ServiceEndpointHashes> service_endpoint_type_hashes(std::string_view service) {
  if (!carried_service(service)) {
    return Error{
        "\"" + std::string(service) +
        "\" is not a service rbsim carries (pkg/srv/Name, or pkg/action/Name_SendGoal or _GetResult)"};
  }
  auto request = type_hash(std::string(service) + std::string(kRequest));
  if (!request) return request.error();
  auto reply = type_hash(std::string(service) + std::string(kResponse));
  if (!reply) return reply.error();
  return ServiceEndpointHashes{std::move(request.value()), std::move(reply.value())};
}

std::string typehash_user_data(std::string_view hash) {
  return "typehash=" + std::string(hash) + ";";
}

}  // namespace rbsim::msgs
