// The control services as the Foxglove server offers them: their specs (the .srv texts split into
// ros2msg request and response schemas) and the request and response payloads in either encoding
// (cdr: rbsim/interfaces.hpp's codecs; json: the fields by name). The request -> Command and
// result -> response mapping is the control module's, shared with the node's DDS services.
#pragma once

#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "rbsim/control.hpp"
#include "rbsim/foxglove.hpp"

namespace rbsim::foxglove::detail {

// control::control_services() in order (service id i + 1 is entry i), named <node>/<name>.
std::vector<ServiceSpec> control_service_specs(std::string_view node);
// A request payload in `encoding` ("cdr" or "json") as its Command; the error names what is wrong.
Result<control::Command> decode_request(const control::ControlService& service, std::string_view encoding,
                                        std::string_view payload);
// The result as the service's response payload in `encoding`.
std::string encode_response(const control::ControlService& service, std::string_view encoding,
                            const control::CommandResult& result);

// A client's message on <node>/command_in (`encoding` cdr or json) as its Command
// (src/command_in.cpp); its step and source are the caller's to set. A set_parameters naming a
// parameter not in `known` (the node's, by name) or more values than it has is refused here, so the
// run loop's work stays bounded. The error names what is wrong.
Result<control::Command> decode_command(std::string_view encoding, std::string_view payload,
                                        const std::unordered_map<std::string, std::size_t>& known);

}  // namespace rbsim::foxglove::detail
