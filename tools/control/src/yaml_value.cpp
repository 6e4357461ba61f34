// YAML values typed as rcl_yaml_param_parser types them (yaml_value.hpp).
#include "yaml_value.hpp"

#include <array>
#include <cerrno>
#include <cstdlib>
#include <string_view>

namespace rbsim::control {

namespace {
constexpr std::string_view kStrTag = "tag:yaml.org,2002:str";
constexpr std::array<std::string_view, 11> kTrue = {"Y",    "y",    "yes", "Yes", "YES", "true",
                                                    "True", "TRUE", "on",  "On",  "ON"};
constexpr std::array<std::string_view, 11> kFalse = {"N",     "n",     "no",  "No",  "NO", "false",
                                                     "False", "FALSE", "off", "Off", "OFF"};
constexpr std::array<std::string_view, 12> kSpecialDoubles = {
    ".nan", ".NaN", ".NAN", ".inf", ".Inf", ".INF", "+.inf", "+.Inf", "+.INF", "-.inf", "-.Inf", "-.INF"};

bool one_of(std::string_view s, const auto& words) {
  for (std::string_view w : words) {
    if (s == w) return true;
  }
  return false;
}

}  // namespace

// One scalar typed as rcl_yaml_param_parser types it: a string tag or quotes make a string; then
// bool words, a whole strtoll (base 0), a whole strtod (with YAML's .nan and .inf), else string.
ParameterValue yaml_scalar(const YAML::Node& node) {
  const std::string& s = node.Scalar();
  if (node.Tag() == kStrTag || node.Tag() == "!") return ParameterValue::of_string(s);  // "!": quoted
  if (one_of(s, kTrue)) return ParameterValue::of_bool(true);
  if (one_of(s, kFalse)) return ParameterValue::of_bool(false);
  if (!s.empty()) {
    char* end = nullptr;
    errno = 0;
    const long long i = std::strtoll(s.c_str(), &end, 0);
    if (errno == 0 && end != s.c_str() && *end == '\0') return ParameterValue::of_integer(i);
    std::string number = s;
    if (one_of(s, kSpecialDoubles)) {
      const bool negative = s.front() == '-';
      number = std::string(negative ? "-" : "") + s.substr(s.find('.') + 1);  // "-.inf" -> "-inf"
    }
    errno = 0;
    end = nullptr;
    const double d = std::strtod(number.c_str(), &end);
    if (errno == 0 && end != number.c_str() && *end == '\0') return ParameterValue::of_double(d);
  }
  return ParameterValue::of_string(s);
}

std::string yaml_line(const std::string& path, const YAML::Node& node) {
  return path + ":" + std::to_string(node.Mark().line + 1);
}

// A parameter's value: a scalar or a sequence of scalars of one type.
Result<ParameterValue> yaml_value(const YAML::Node& node) {
  if (node.IsNull()) return Error{"no value"};
  if (node.IsScalar()) return yaml_scalar(node);
  if (!node.IsSequence()) return Error{"a value must be a scalar or a sequence of scalars (got a map)"};
  if (node.size() == 0) return Error{"an empty sequence has no type"};
  ParameterValue out;
  for (std::size_t k = 0; k < node.size(); ++k) {
    if (!node[k].IsScalar()) return Error{"a sequence may hold only scalars"};
    const ParameterValue item = yaml_scalar(node[k]);
    const auto array = static_cast<ParameterType>(static_cast<int>(item.type) + 5);  // Bool -> BoolArray, ...
    if (k == 0) out.type = array;
    if (out.type != array) {
      return Error{std::string("sequence should be of one type: element ") + std::to_string(k) + " is " +
                   to_string(item.type) + ", the first is " +
                   to_string(static_cast<ParameterType>(static_cast<int>(out.type) - 5))};
    }
    out.bool_array_value.push_back(item.bool_value);
    out.integer_array_value.push_back(item.integer_value);
    out.double_array_value.push_back(item.double_value);
    out.string_array_value.push_back(item.string_value);
  }
  // Keep only the field the type names.
  if (out.type != ParameterType::BoolArray) out.bool_array_value.clear();
  if (out.type != ParameterType::IntegerArray) out.integer_array_value.clear();
  if (out.type != ParameterType::DoubleArray) out.double_array_value.clear();
  if (out.type != ParameterType::StringArray) out.string_array_value.clear();
  return out;
}

}  // namespace rbsim::control
