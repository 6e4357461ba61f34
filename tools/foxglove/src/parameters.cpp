// The parameter ops of the Foxglove protocol: setParameters values typed from JSON, and
// parameterValues written as the Foxglove SDK writes them.
#include <algorithm>
#include <cstring>

#include "parameter_requests.hpp"
#include "protocol_util.hpp"

namespace rbsim::foxglove {

using detail::shown;

namespace {
constexpr char kBase64[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

std::string base64(const std::vector<std::uint8_t>& bytes) {
  std::string out;
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    const std::size_t in = std::min<std::size_t>(3, bytes.size() - i);
    std::uint32_t n = std::uint32_t{bytes[i]} << 16;
    if (in > 1) n |= std::uint32_t{bytes[i + 1]} << 8;
    if (in > 2) n |= std::uint32_t{bytes[i + 2]};
    for (std::size_t k = 0; k < 4; ++k) out.push_back(k <= in ? kBase64[(n >> (18 - 6 * k)) & 63] : '=');
  }
  return out;
}

// Standard base64 with padding; nullopt for anything else.
std::optional<std::vector<std::uint8_t>> unbase64(const std::string& text) {
  if (text.size() % 4 != 0) return std::nullopt;
  std::vector<std::uint8_t> out;
  out.reserve(text.size() / 4 * 3);
  for (std::size_t i = 0; i < text.size(); i += 4) {
    std::uint32_t n = 0;
    int pad = 0;
    for (std::size_t k = 0; k < 4; ++k) {
      const char c = text[i + k];
      const char* at = c == '\0' ? nullptr : std::strchr(kBase64, c);
      if (c == '=' && i + 4 == text.size() && k >= 2) {
        ++pad;
        n <<= 6;
        continue;
      }
      if (at == nullptr || pad > 0) return std::nullopt;
      n = (n << 6) | static_cast<std::uint32_t>(at - kBase64);
    }
    out.push_back(static_cast<std::uint8_t>(n >> 16));
    if (pad < 2) out.push_back(static_cast<std::uint8_t>((n >> 8) & 0xff));
    if (pad < 1) out.push_back(static_cast<std::uint8_t>(n & 0xff));
  }
  return out;
}

nlohmann::json parameter_json(const msgs::Parameter& p) {
  using T = msgs::ParameterType;
  const msgs::ParameterValue& v = p.value;
  nlohmann::json j = {{"name", p.name}};
  switch (v.type) {
    case T::Bool:
      j["value"] = v.bool_value;
      break;
    case T::Integer:
      j["value"] = v.integer_value;
      break;
    case T::Double:
      j["value"] = v.double_value;
      j["type"] = "float64";
      break;
    case T::String:
      j["value"] = v.string_value;
      break;
    case T::ByteArray:
      j["value"] = base64(v.byte_array_value);
      j["type"] = "byte_array";
      break;
    case T::BoolArray:
      j["value"] = v.bool_array_value;
      break;
    case T::IntegerArray:
      j["value"] = v.integer_array_value;
      break;
    case T::DoubleArray:
      j["value"] = v.double_array_value;
      j["type"] = "float64_array";
      break;
    case T::StringArray:
      j["value"] = v.string_array_value;
      break;
    default:
      break;  // not set: no value
  }
  return j;
}
}  // namespace

std::string parameter_values_json(std::span<const msgs::Parameter> parameters,
                                  const std::optional<std::string>& id) {
  nlohmann::json list = nlohmann::json::array();
  for (const msgs::Parameter& p : parameters) list.push_back(parameter_json(p));
  nlohmann::json j = {{"op", "parameterValues"}, {"parameters", std::move(list)}};
  if (id) j["id"] = *id;
  return j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

namespace detail {

namespace {
// A setParameters value as JSON types it (ParameterRequest::values); "" or what is wrong.
std::string typed_value(const nlohmann::json& v, const std::string& hint, msgs::ParameterValue& out,
                        bool& untyped_integer) {
  using T = msgs::ParameterType;
  untyped_integer = false;
  out = msgs::ParameterValue{};
  if (!hint.empty() && hint != "float64" && hint != "float64_array" && hint != "byte_array")
    return "unknown type " + shown(hint) + " (float64, float64_array or byte_array)";
  if (hint == "float64") {
    if (!v.is_number()) return "type float64 needs a number";
    out = msgs::ParameterValue::of_double(v.get<double>());
    return "";
  }
  if (hint == "byte_array") {
    if (!v.is_string()) return "type byte_array needs a base64 string";
    auto bytes = unbase64(v.get<std::string>());
    if (!bytes) return "type byte_array: not valid base64";
    out.type = T::ByteArray;
    out.byte_array_value = std::move(*bytes);
    return "";
  }
  if (hint == "float64_array") {
    if (!v.is_array()) return "type float64_array needs an array of numbers";
    out.type = T::DoubleArray;
    for (const nlohmann::json& e : v) {
      if (!e.is_number()) return "type float64_array needs an array of numbers";
      out.double_array_value.push_back(e.get<double>());
    }
    return "";
  }
  if (v.is_boolean()) {
    out = msgs::ParameterValue::of_bool(v.get<bool>());
  } else if (v.is_number_unsigned() && v.get<std::uint64_t>() > static_cast<std::uint64_t>(INT64_MAX)) {
    return "integer " + shown(v) + " out of range";
  } else if (v.is_number_integer()) {
    out = msgs::ParameterValue::of_integer(v.get<std::int64_t>());
    untyped_integer = true;
  } else if (v.is_number()) {
    out = msgs::ParameterValue::of_double(v.get<double>());
  } else if (v.is_string()) {
    out = msgs::ParameterValue::of_string(v.get<std::string>());
  } else if (v.is_array()) {
    if (v.empty()) return "an empty array has no type: give a typed value";
    const auto all = [&](auto pred) { return std::all_of(v.begin(), v.end(), pred); };
    if (all([](const nlohmann::json& e) { return e.is_boolean(); })) {
      out.type = T::BoolArray;
      for (const nlohmann::json& e : v) out.bool_array_value.push_back(e.get<bool>());
    } else if (all([](const nlohmann::json& e) {
                 return e.is_number_integer() &&
                        !(e.is_number_unsigned() && e.get<std::uint64_t>() > INT64_MAX);
               })) {
      out.type = T::IntegerArray;
      for (const nlohmann::json& e : v) out.integer_array_value.push_back(e.get<std::int64_t>());
    } else if (all([](const nlohmann::json& e) { return e.is_number(); })) {
      out.type = T::DoubleArray;
      for (const nlohmann::json& e : v) out.double_array_value.push_back(e.get<double>());
    } else if (all([](const nlohmann::json& e) { return e.is_string(); })) {
      out.type = T::StringArray;
      for (const nlohmann::json& e : v) out.string_array_value.push_back(e.get<std::string>());
    } else {
      return "an array must hold booleans, numbers or strings, not a mix";
    }
  } else if (v.is_null()) {
    return "no value: parameters cannot be unset";
  } else {
    return "value " + shown(v) + " is not a parameter value";
  }
  return "";
}

}  // namespace

void parameter_op(const std::string& op, const nlohmann::json& j, ClientProtocol::Outcome& out,
                  Problems& problems) {
  ParameterRequest r;
  r.op = op == "getParameters"               ? ParameterRequest::Op::Get
         : op == "setParameters"             ? ParameterRequest::Op::Set
         : op == "subscribeParameterUpdates" ? ParameterRequest::Op::Subscribe
                                             : ParameterRequest::Op::Unsubscribe;
  if (const auto id = j.find("id");
      id != j.end() && (r.op == ParameterRequest::Op::Get || r.op == ParameterRequest::Op::Set)) {
    if (!id->is_string()) {
      problems.add(op + ": \"id\" must be a string");
      return;
    }
    r.id = id->get<std::string>();
  }
  if (r.op != ParameterRequest::Op::Set) {
    const auto names = j.find("parameterNames");
    if (names == j.end() || !names->is_array()) {
      problems.add(op + ": \"parameterNames\" must be an array of strings");
      return;
    }
    for (const nlohmann::json& n : *names) {
      if (n.is_string()) {
        r.names.push_back(n.get<std::string>());
      } else {
        problems.add(op + ": parameter name " + shown(n) + " is not a string");
      }
    }
    if (r.names.empty() && !names->empty()) return;  // nothing valid: not "every parameter"
    out.parameters = std::move(r);
    return;
  }
  const auto list = j.find("parameters");
  if (list == j.end() || !list->is_array()) {
    problems.add("setParameters: \"parameters\" must be an array");
    return;
  }
  for (const nlohmann::json& e : *list) {
    const auto name = e.is_object() ? e.find("name") : e.end();
    if (!e.is_object() || name == e.end() || !name->is_string()) {
      problems.add("setParameters: entry " + shown(e) + " needs a \"name\" string");
      continue;
    }
    const auto type = e.find("type");
    if (type != e.end() && !type->is_string()) {
      problems.add("setParameters: parameter " + shown(*name) + ": \"type\" must be a string");
      continue;
    }
    const auto value = e.find("value");
    msgs::Parameter p{name->get<std::string>(), {}};
    bool untyped = false;
    const std::string bad =
        typed_value(value == e.end() ? nlohmann::json() : *value,
                    type == e.end() ? std::string() : type->get<std::string>(), p.value, untyped);
    if (!bad.empty()) {
      problems.add("setParameters: parameter " + shown(*name) + ": " + bad);
      continue;
    }
    r.values.push_back(std::move(p));
    r.untyped_integer.push_back(untyped);
  }
  if (!r.values.empty() || list->empty()) out.parameters = std::move(r);
}

void keep_known_names(ParameterRequest& r, const std::unordered_map<std::string, std::size_t>& index,
                      std::vector<std::string>& problems) {
  std::size_t kept = 0;
  for (std::size_t k = 0; k < r.values.size(); ++k) {
    if (index.count(r.values[k].name) == 0) {
      problems.push_back("no parameter '" + r.values[k].name.substr(0, 200) + "'");
      continue;
    }
    if (kept != k) {
      r.values[kept] = std::move(r.values[k]);
      r.untyped_integer[kept] = r.untyped_integer[k];
    }
    ++kept;
  }
  r.values.resize(kept);
  r.untyped_integer.resize(kept);
  for (const msgs::Parameter& p : r.values) r.names.push_back(p.name);
}

void type_untyped_integers(ParameterRequest& r, const std::vector<msgs::ParameterType>& types) {
  for (std::size_t k = 0; k < r.values.size(); ++k) {
    msgs::ParameterValue& v = r.values[k].value;
    if (r.untyped_integer[k] && types[k] == msgs::ParameterType::Double &&
        v.integer_value >= -(std::int64_t{1} << 53) && v.integer_value <= (std::int64_t{1} << 53)) {
      v = msgs::ParameterValue::of_double(static_cast<double>(v.integer_value));
    }
  }
}

}  // namespace detail

}  // namespace rbsim::foxglove
