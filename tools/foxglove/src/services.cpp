// The control services' specs and payloads for the Foxglove server (src/services.hpp).
#include "services.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstring>
#include <limits>

namespace rbsim::foxglove {

ServiceSpec service_spec(std::string_view node, std::string_view name, std::string_view type) {
  ServiceSpec spec;
  spec.name = std::string(node) + "/" + std::string(name);
  spec.type = std::string(type);
  // rosbag2's ros2msg schema of each half: its part of the .srv text, then every type it uses
  // (simulation_interfaces' requests nest geometry_msgs and their own messages), so a client
  // decodes the call without the types installed. A type we do not carry leaves them empty.
  if (Result<std::string> r = msgs::ros2msg_schema(spec.type + std::string(msgs::kServiceRequestSuffix)))
    spec.request_schema = std::move(r.value());
  if (Result<std::string> r = msgs::ros2msg_schema(spec.type + std::string(msgs::kServiceResponseSuffix)))
    spec.response_schema = std::move(r.value());
  return spec;
}

}  // namespace rbsim::foxglove

namespace rbsim::foxglove::detail {

namespace {
using control::CommandKind;

std::span<const std::byte> as_bytes(std::string_view s) {
  return {reinterpret_cast<const std::byte*>(s.data()), s.size()};
}

// The fields of a JSON request: an object with only these names, numbers of the field's type
// (an unsigned integer within uint32 for `u32`, any number for a double); absent fields are 0.
struct JsonFields {
  const nlohmann::json& object;
  std::string type;
  std::string error;
  void u32(const char* name, std::uint32_t& out) {
    const auto it = object.find(name);
    if (it == object.end() || !error.empty()) return;
    if (!it->is_number_integer() || it->get<std::int64_t>() < 0 ||
        it->get<std::uint64_t>() > std::numeric_limits<std::uint32_t>::max()) {
      error = type + ": field '" + name + "' must be an integer in [0, 2^32)";
      return;
    }
    out = static_cast<std::uint32_t>(it->get<std::uint64_t>());
  }
  void f64(const char* name, double& out) {
    const auto it = object.find(name);
    if (it == object.end() || !error.empty()) return;
    if (!it->is_number()) {
      error = type + ": field '" + name + "' must be a number";
      return;
    }
    out = it->get<double>();
  }
  void only(std::initializer_list<const char*> names) {
    for (const auto& [key, value] : object.items()) {
      (void)value;
      if (!error.empty()) return;
      bool known = false;
      for (const char* n : names) known = known || key == n;
      if (!known) error = type + ": no field '" + key.substr(0, 40) + "'";
    }
  }
};

template <class Request>
Result<Request> decode_cdr(std::string_view payload) {
  Request r;
  if (Status st = msgs::decode(as_bytes(payload), r); !st) return st.error();
  return r;
}
}  // namespace

std::vector<ServiceSpec> control_service_specs(std::string_view node) {
  std::vector<ServiceSpec> specs;
  for (const control::ControlService& s : control::control_services())
    specs.push_back(service_spec(node, s.name, s.type));
  return specs;
}

Result<control::Command> decode_request(const control::ControlService& service, std::string_view encoding,
                                        std::string_view payload) {
  if (encoding == "cdr") {
    if (service.kind == CommandKind::Step) {
      auto r = decode_cdr<msgs::StepRequest>(payload);
      if (!r) return r.error();
      return control::command_for(r.value());
    }
    if (service.kind == CommandKind::Impulse) {
      auto r = decode_cdr<msgs::ApplyImpulseRequest>(payload);
      if (!r) return r.error();
      return control::command_for(r.value());
    }
    auto r = decode_cdr<msgs::TriggerRequest>(payload);
    if (!r) return r.error();
    return control::command_for(service.kind, r.value());
  }
  const nlohmann::json j = nlohmann::json::parse(payload.begin(), payload.end(), nullptr, false);
  const std::string type = std::string(service.type) + "_Request";
  if (j.is_discarded() || !j.is_object()) return Error{type + ": the json request is not a JSON object"};
  JsonFields f{j, type, {}};
  if (service.kind == CommandKind::Step) {
    msgs::StepRequest r;
    f.only({"steps"});
    f.u32("steps", r.steps);
    if (!f.error.empty()) return Error{f.error};
    return control::command_for(r);
  }
  if (service.kind == CommandKind::Impulse) {
    msgs::ApplyImpulseRequest r;
    f.only({"body", "jx", "jy", "px", "py"});
    f.u32("body", r.body);
    f.f64("jx", r.jx);
    f.f64("jy", r.jy);
    f.f64("px", r.px);
    f.f64("py", r.py);
    if (!f.error.empty()) return Error{f.error};
    return control::command_for(r);
  }
  f.only({});
  if (!f.error.empty()) return Error{f.error};
  return control::command_for(service.kind, msgs::TriggerRequest{});
}

std::string encode_response(const control::ControlService& service, std::string_view encoding,
                            const control::CommandResult& result) {
  if (encoding == "cdr") {
    Bytes out;
    if (service.kind == CommandKind::Step) {
      msgs::encode(control::step_response(result), out);
    } else if (service.kind == CommandKind::Impulse) {
      msgs::encode(control::impulse_response(result), out);
    } else {
      msgs::encode(control::trigger_response(result), out);
    }
    return std::string(reinterpret_cast<const char*>(out.data()), out.size());
  }
  nlohmann::json j;
  if (service.kind == CommandKind::Step) {
    const msgs::StepResponse r = control::step_response(result);
    j = {{"success", r.success}, {"message", r.message}, {"step", r.step}};
  } else if (service.kind == CommandKind::Impulse) {
    const msgs::ApplyImpulseResponse r = control::impulse_response(result);
    j = {{"success", r.success}, {"message", r.message}, {"step", r.step}};
  } else {
    const msgs::TriggerResponse r = control::trigger_response(result);
    j = {{"success", r.success}, {"message", r.message}};
  }
  return j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace rbsim::foxglove::detail
