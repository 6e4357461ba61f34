// --ros-args: -p NAME:=VALUE and --params-file FILE, typed as rcl types them (yaml-cpp parses).
#include "rbsim/ros_args.hpp"

#include <yaml-cpp/yaml.h>

#include <array>
#include <cerrno>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <utility>

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

// One scalar typed as rcl_yaml_param_parser types it: a string tag or quotes make a string; then
// bool words, a whole strtoll (base 0), a whole strtod (with YAML's .nan and .inf), else string.
ParameterValue scalar(const YAML::Node& node) {
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

std::string line_of(const std::string& path, const YAML::Node& node) {
  return path + ":" + std::to_string(node.Mark().line + 1);
}

// A parameter's value: a scalar or a sequence of scalars of one type.
Result<ParameterValue> value_of(const YAML::Node& node) {
  if (node.IsNull()) return Error{"no value"};
  if (node.IsScalar()) return scalar(node);
  if (!node.IsSequence()) return Error{"a value must be a scalar or a sequence of scalars (got a map)"};
  if (node.size() == 0) return Error{"an empty sequence has no type"};
  ParameterValue out;
  for (std::size_t k = 0; k < node.size(); ++k) {
    if (!node[k].IsScalar()) return Error{"a sequence may hold only scalars"};
    const ParameterValue item = scalar(node[k]);
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

std::vector<std::string> segments(std::string_view name) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (start <= name.size()) {
    const std::size_t slash = name.find('/', start);
    const std::string_view part =
        name.substr(start, slash == std::string_view::npos ? name.npos : slash - start);
    if (!part.empty()) out.emplace_back(part);
    if (slash == std::string_view::npos) break;
    start = slash + 1;
  }
  return out;
}

bool match(const std::vector<std::string>& p, std::size_t i, const std::vector<std::string>& n,
           std::size_t j) {
  if (i == p.size()) return j == n.size();
  if (p[i] == "**") {
    for (std::size_t k = j; k <= n.size(); ++k) {
      if (match(p, i + 1, n, k)) return true;
    }
    return false;
  }
  if (j == n.size()) return false;
  return (p[i] == "*" || p[i] == n[j]) && match(p, i + 1, n, j + 1);
}

struct FileParser {
  const std::string& path;
  const std::string& node_name;
  std::vector<ParameterOverride> out;

  Status parameters(const YAML::Node& map, const std::string& prefix, bool wildcard) {
    for (const auto& kv : map) {
      const std::string key = kv.first.Scalar();
      const std::string name = prefix.empty() ? key : prefix + "." + key;
      if (kv.second.IsMap()) {
        if (Status st = parameters(kv.second, name, wildcard); !st) return st;
        continue;
      }
      Result<ParameterValue> value = value_of(kv.second);
      if (!value) {
        return Error{line_of(path, kv.second.IsNull() ? kv.first : kv.second) + ": parameter '" + name +
                         "': " + value.error().message,
                     ErrorCode::InvalidArgument};
      }
      out.push_back({{name, std::move(value.value())}, line_of(path, kv.second), wildcard});
    }
    return Ok{};
  }

  Status nodes(const YAML::Node& map, std::vector<std::string>& keys) {
    for (const auto& kv : map) {
      const std::string key = kv.first.IsScalar() ? kv.first.Scalar() : "";
      if (key == "ros__parameters") {
        if (!kv.second.IsMap()) {
          return Error{line_of(path, kv.first) + ": ros__parameters must be a map of parameters",
                       ErrorCode::InvalidArgument};
        }
        std::string pattern;
        for (const std::string& k : keys) pattern += "/" + k;
        if (!node_name_matches(pattern, node_name)) continue;
        const bool wildcard = pattern.find('*') != std::string::npos;
        if (Status st = parameters(kv.second, "", wildcard); !st) return st;
      } else if (!key.empty() && kv.second.IsMap()) {
        const std::vector<std::string> parts = segments(key);
        keys.insert(keys.end(), parts.begin(), parts.end());
        const Status st = nodes(kv.second, keys);
        keys.resize(keys.size() - parts.size());
        if (!st) return st;
      } else {
        return Error{
            line_of(path, kv.first) + ": expected a node name holding ros__parameters (got '" + key + "')",
            ErrorCode::InvalidArgument};
      }
    }
    return Ok{};
  }
};

}  // namespace

bool node_name_matches(std::string_view pattern, std::string_view node_name) {
  return match(segments(pattern), 0, segments(node_name), 0);
}

std::vector<std::string> take_ros_args(std::vector<std::string>& args) {
  std::vector<std::string> taken, kept;
  bool inside = false;
  for (std::string& a : args) {
    if (a == "--ros-args") {
      inside = true;
    } else if (inside && a == "--") {
      inside = false;
    } else if (inside) {
      taken.push_back(std::move(a));
    } else {
      kept.push_back(std::move(a));
    }
  }
  args = std::move(kept);
  return taken;
}

Result<ParameterValue> parse_parameter_value(std::string_view text) {
  try {
    const YAML::Node node = YAML::Load(std::string(text));
    return value_of(node);
  } catch (const YAML::Exception& e) {
    return Error{"not valid YAML: " + e.msg};
  }
}

Result<std::vector<ParameterOverride>> parse_params_yaml(std::string_view text, const std::string& path,
                                                         const std::string& node_name) {
  FileParser parser{path, node_name, {}};
  try {
    const YAML::Node root = YAML::Load(std::string(text));
    if (!root.IsMap()) {
      return Error{path + ":" + std::to_string(root.Mark().line + 1) +
                       ": expected node names at the top level (/NS: or /**: then ros__parameters:)",
                   ErrorCode::InvalidArgument};
    }
    std::vector<std::string> keys;
    if (Status st = parser.nodes(root, keys); !st) return st.error();
  } catch (const YAML::Exception& e) {
    return Error{path + ":" + std::to_string(e.mark.line + 1) + ": not valid YAML: " + e.msg,
                 ErrorCode::InvalidArgument};
  }
  return std::move(parser.out);
}

Result<std::vector<ParameterOverride>> parse_params_file(const std::string& path,
                                                         const std::string& node_name) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Error{path + ": cannot read the parameters file", ErrorCode::IoError};
  std::ostringstream text;
  text << in.rdbuf();
  return parse_params_yaml(text.str(), path, node_name);
}

Result<std::vector<ParameterOverride>> parse_ros_args(const std::vector<std::string>& tokens,
                                                      const std::string& node_name) {
  std::vector<ParameterOverride> out;
  for (std::size_t i = 0; i < tokens.size(); ++i) {
    const std::string& t = tokens[i];
    const bool param = t == "-p" || t == "--param";
    if (!param && t != "--params-file") {
      return Error{
          "--ros-args: '" + t + "' is not supported (rbsim reads -p NAME:=VALUE and --params-file FILE)",
          ErrorCode::InvalidArgument};
    }
    if (i + 1 == tokens.size())
      return Error{"--ros-args: " + t + " needs a value", ErrorCode::InvalidArgument};
    const std::string& arg = tokens[++i];
    if (!param) {
      Result<std::vector<ParameterOverride>> file = parse_params_file(arg, node_name);
      if (!file) return file.error();
      for (ParameterOverride& o : file.value()) out.push_back(std::move(o));
      continue;
    }
    const std::size_t assign = arg.find(":=");
    if (assign == std::string::npos || assign == 0) {
      return Error{t + " " + arg + ": expected NAME:=VALUE", ErrorCode::InvalidArgument};
    }
    const std::string name = arg.substr(0, assign);
    Result<ParameterValue> value = parse_parameter_value(std::string_view(arg).substr(assign + 2));
    if (!value) {
      return Error{t + " " + arg + ": parameter '" + name + "': " + value.error().message,
                   ErrorCode::InvalidArgument};
    }
    out.push_back({{name, std::move(value.value())}, t + " " + arg, false});
  }
  return out;
}

}  // namespace rbsim::control
