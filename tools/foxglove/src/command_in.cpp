// A client's message on <node>/command_in as a Command (src/services.hpp): cdr is the CDR of
// rbsim_msgs/msg/Command (msgs::decode); json is the same fields by name, every one optional
// (absent: its default), with the parameters as rcl_interfaces/msg/Parameter objects
// ({"name": ..., "value": {"type": 3, "double_value": 2.5}}). Either way control::from_message
// makes the Command; the caller sets when it applies and its source.
#include <nlohmann/json.hpp>

#include <limits>

#include "protocol_util.hpp"
#include "services.hpp"

namespace rbsim::foxglove::detail {

namespace {
using Json = nlohmann::json;

// Reads the fields of one JSON object into their C++ types; the first problem is kept.
struct Fields {
  const Json& object;
  std::string where;
  std::string& error;

  const Json* find(const char* name) const {
    if (!error.empty()) return nullptr;
    const auto it = object.find(name);
    return it == object.end() ? nullptr : &*it;
  }
  void fail(const char* name, const char* what) { error = where + "field '" + name + "' must be " + what; }
  template <class T>
  static bool integer(const Json& v, T& out) {
    if (!v.is_number_integer()) return false;
    if (v.is_number_unsigned()) {
      const auto u = v.get<std::uint64_t>();
      if (u > static_cast<std::uint64_t>(std::numeric_limits<T>::max())) return false;
      out = static_cast<T>(u);
      return true;
    }
    const auto s = v.get<std::int64_t>();
    if (s < static_cast<std::int64_t>(std::numeric_limits<T>::min())) return false;
    if (s > 0 && static_cast<std::uint64_t>(s) > static_cast<std::uint64_t>(std::numeric_limits<T>::max()))
      return false;
    out = static_cast<T>(s);
    return true;
  }
  // One value of a field's type; false (and `what` says what it must be) when it is not one.
  template <class T>
  static bool value_of(const Json& v, T& out, const char*& what) {
    if constexpr (std::is_same_v<T, bool>) {
      what = "true or false";
      if (!v.is_boolean()) return false;
      out = v.get<bool>();
    } else if constexpr (std::is_same_v<T, double>) {
      what = "a number";
      if (!v.is_number()) return false;
      out = v.get<double>();
    } else if constexpr (std::is_same_v<T, std::string>) {
      what = "a string";
      if (!v.is_string()) return false;
      out = v.get<std::string>();
    } else {
      what = "an integer in its type's range";
      return integer(v, out);
    }
    return true;
  }
  template <class T>
  void get(const char* name, T& out) {
    const char* what = "";
    if (const Json* v = find(name); v != nullptr && !value_of(*v, out, what)) fail(name, what);
  }
  template <class T>
  void array(const char* name, std::vector<T>& out) {
    const Json* v = find(name);
    if (v == nullptr) return;
    if (!v->is_array()) return fail(name, "an array");
    const char* what = "";
    for (const Json& item : *v) {
      T value{};
      if (!value_of(item, value, what)) {
        error = where + "field '" + name + "' must be an array of " + what;
        return;
      }
      out.push_back(std::move(value));
    }
  }
  void only(std::initializer_list<const char*> names) {
    for (const auto& item : object.items()) {
      if (!error.empty()) return;
      bool known = false;
      for (const char* n : names) known = known || item.key() == n;
      if (!known) error = where + "no field '" + item.key().substr(0, 40) + "'";
    }
  }
};

void read_parameter(const Json& j, const std::string& where, msgs::Parameter& p, std::string& error) {
  if (!j.is_object()) {
    error = where + "not an object";
    return;
  }
  Fields f{j, where, error};
  f.only({"name", "value"});
  f.get("name", p.name);
  const Json* value = f.find("value");
  if (value == nullptr) return;
  if (!value->is_object()) return f.fail("value", "an object");
  msgs::ParameterValue& v = p.value;
  Fields g{*value, where + "value: ", error};
  g.only({"type", "bool_value", "integer_value", "double_value", "string_value", "byte_array_value",
          "bool_array_value", "integer_array_value", "double_array_value", "string_array_value"});
  std::uint8_t type = 0;
  g.get("type", type);
  v.type = static_cast<msgs::ParameterType>(type);
  g.get("bool_value", v.bool_value);
  g.get("integer_value", v.integer_value);
  g.get("double_value", v.double_value);
  g.get("string_value", v.string_value);
  g.array("byte_array_value", v.byte_array_value);
  g.array("bool_array_value", v.bool_array_value);
  g.array("integer_array_value", v.integer_array_value);
  g.array("double_array_value", v.double_array_value);
  g.array("string_array_value", v.string_array_value);
}

Result<msgs::CommandMessage> from_json(std::string_view payload, std::size_t max_parameters) {
  const std::string type(kCommandInSchema);
  if (too_deep(payload)) return Error{type + ": JSON nested deeper than " + std::to_string(kMaxDepth)};
  const Json j = Json::parse(payload.begin(), payload.end(), nullptr, false);
  if (j.is_discarded() || !j.is_object()) return Error{type + ": the json message is not a JSON object"};
  std::string error;
  Fields f{j, type + ": ", error};
  // The recorded fields (seq, step, stamp, source, success, message) are taken and not used.
  f.only({"seq", "step", "stamp", "kind", "source", "parameters", "atomic", "steps", "pause_seconds", "body",
          "jx", "jy", "px", "py", "success", "message"});
  msgs::CommandMessage m;
  f.get("kind", m.kind);
  f.get("atomic", m.atomic);
  f.get("steps", m.steps);
  f.get("pause_seconds", m.pause_seconds);
  f.get("body", m.body);
  f.get("jx", m.jx);
  f.get("jy", m.jy);
  f.get("px", m.px);
  f.get("py", m.py);
  if (const Json* list = f.find("parameters")) {
    if (!list->is_array()) {
      f.fail("parameters", "an array");
    } else if (list->size() > max_parameters) {
      error = "set_parameters: " + std::to_string(list->size()) + " values, more than the node's " +
              std::to_string(max_parameters) + " parameters";
    } else {
      m.parameters.resize(list->size());
      for (std::size_t k = 0; k < list->size() && error.empty(); ++k) {
        read_parameter((*list)[k], type + ": parameters[" + std::to_string(k) + "]: ", m.parameters[k],
                       error);
      }
    }
  }
  if (!error.empty()) return Error{error};
  return m;
}
}  // namespace

Result<control::Command> decode_command(std::string_view encoding, std::string_view payload,
                                        const std::unordered_map<std::string, std::size_t>& known) {
  msgs::CommandMessage m;
  if (encoding == "cdr") {
    if (Status st = msgs::decode({reinterpret_cast<const std::byte*>(payload.data()), payload.size()}, m);
        !st)
      return st.error();
  } else {
    Result<msgs::CommandMessage> r = from_json(payload, known.size());
    if (!r) return r.error();
    m = std::move(r.value());
  }
  if (m.kind == msgs::CommandMessage::SetParameters) {
    if (m.parameters.size() > known.size()) {
      return Error{"set_parameters: " + std::to_string(m.parameters.size()) +
                   " values, more than the node's " + std::to_string(known.size()) + " parameters"};
    }
    for (const msgs::Parameter& p : m.parameters) {
      if (known.count(p.name) == 0)
        return Error{"set_parameters: no parameter '" + p.name.substr(0, 200) + "'"};
    }
  }
  m.step = 0;  // when it applies is the server's to say (from_message checks the rest)
  return control::from_message(m);
}

}  // namespace rbsim::foxglove::detail
