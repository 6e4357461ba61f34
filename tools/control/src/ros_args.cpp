// --ros-args: -p NAME:=VALUE and --params-file FILE, typed as rcl types them (yaml-cpp parses).
#include "rbsim/ros_args.hpp"

#include "rbsim/read_file.hpp"
#include "yaml_value.hpp"

#include <yaml-cpp/yaml.h>

#include <utility>

namespace rbsim::control {

namespace {

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
      Result<ParameterValue> value = yaml_value(kv.second);
      if (!value) {
        return with_context(
            yaml_line(path, kv.second.IsNull() ? kv.first : kv.second) + ": parameter '" + name + "': ",
            value.error(), ErrorCode::InvalidArgument);
      }
      out.push_back({{name, std::move(value.value())}, yaml_line(path, kv.second), wildcard});
    }
    return Ok{};
  }

  Status nodes(const YAML::Node& map, std::vector<std::string>& keys) {
    for (const auto& kv : map) {
      const std::string key = kv.first.IsScalar() ? kv.first.Scalar() : "";
      if (key == "ros__parameters") {
        if (!kv.second.IsMap()) {
          return Error{yaml_line(path, kv.first) + ": ros__parameters must be a map of parameters",
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
            yaml_line(path, kv.first) + ": expected a node name holding ros__parameters (got '" + key + "')",
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
    return yaml_value(node);
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
  Result<std::string> text = read_text_file(path, "the parameters file");
  if (!text) return text.error();
  return parse_params_yaml(text.value(), path, node_name);
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
      return with_context(t + " " + arg + ": parameter '" + name + "': ", value.error(),
                          ErrorCode::InvalidArgument);
    }
    out.push_back({{name, std::move(value.value())}, t + " " + arg, false});
  }
  return out;
}

}  // namespace rbsim::control
